// A problem with one constant of a material law, found by its *_check function.
#pragma once

#include <string>

namespace crater::materials {

struct ConstantProblem {
  std::string key;      // the scenario key of the constant at fault ("r1", "b_pa"), or "" for
                        // the set as a whole
  std::string message;  // what is wrong and, where it can tell, the likely fix
};

}  // namespace crater::materials
