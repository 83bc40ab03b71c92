// libFuzzer target: the Gmsh MSH 4.1 reader (mesh::parse_gmsh) and the FEM part's use of what it
// returns (fem::mesh_from_gmsh: element selection, node compaction, orientation, node sets).
//
// Expected outcomes: a mesh, or an InputError (exit 2: the file is wrong). Anything else that
// escapes -- another exception, a crash, a sanitizer report, a hang, gigabytes of memory -- is a
// finding; the input goes to tests/fuzz/crashes/gmsh/ once reported and fixed.
//
// Input: the bytes of a .msh file. The part's elements are taken from the whole mesh (no
// group), in the dimension the reader reports.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <string_view>
#include <typeinfo>

#include "core/error.hpp"
#include "fem/fem_mesh_source.hpp"
#include "mesh/gmsh.hpp"

namespace {

[[noreturn]] void finding(const std::string& what) {
  std::fprintf(stderr, "FINDING: %s\n", what.c_str());
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const crater::mesh::GmshMesh mesh = crater::mesh::parse_gmsh(text, "fuzz.msh");
    crater::Index reordered = 0;
    if (mesh.dimension == 2)
      (void)crater::fem::mesh_from_gmsh<2>(mesh, "fuzz.msh", "", reordered);
    else if (mesh.dimension == 3)
      (void)crater::fem::mesh_from_gmsh<3>(mesh, "fuzz.msh", "", reordered);
    else
      finding("parse_gmsh returned a mesh of dimension " + std::to_string(mesh.dimension));
  } catch (const crater::InputError&) {
    // expected: a bad file (exit 2)
  } catch (const std::exception& e) {
    finding(std::string("escaped ") + typeid(e).name() + ": " + e.what());
  } catch (...) {
    finding("escaped a non-std exception");
  }
  return 0;
}
