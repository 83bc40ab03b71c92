// On several MPI ranks, the parts as the probes and gauges read them (issue 29,
// docs/distributed.md): a spread part gathered whole on the root rank, in the order of its
// frames (ascending id; an FEM part's nodes and elements in their numbering), behind the reading
// side of parts::Part (geometry, point and cell fields, count). The other ranks get empty
// stand-ins: what they compute from them is never written. A gathered part does not step.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "parallel/comm.hpp"
#include "parts/part.hpp"

namespace crater::solver {

// What a gathered part is not for (a logic error of the caller). A free function: GCC 12 does
// not see a member's [[noreturn]] in a class template's other members (-Wreturn-type).
[[noreturn]] inline void refuse_gathered(const std::string& name, const char* what) {
  throw std::logic_error("gathered part '" + name + "' is for reading: " + what);
}

template <int D>
class GatheredPart final : public parts::Part<D> {
 public:
  GatheredPart(std::string name, const char* method, parts::GatheredPoints<D> g)
      : name_(std::move(name)), method_(method), g_(std::move(g)) {}

  const std::string& name() const override { return name_; }
  const char* method() const override { return method_; }
  /// The entities gathered: elements of a mesh part (eroded ones too, as its frames hold
  /// them), else points.
  Index count() const override {
    return static_cast<Index>(g_.offsets.empty() ? g_.points.size() : g_.offsets.size());
  }
  parts::Geometry<D> geometry() const override {
    return {&g_.points, g_.connectivity, g_.offsets, g_.cell_types};
  }
  const std::vector<Vec<D>>& points() const override { return g_.points; }
  std::vector<fields::FieldView> point_fields() const override { return g_.point.views(); }
  std::vector<fields::FieldView> cell_fields() const override { return g_.cell.views(); }

  Real mass_kg() const override { refuse_gathered(name_, "mass_kg"); }
  parts::StableStep stable_step() const override { refuse_gathered(name_, "stable_step"); }
  void compute_forces(Real) override { refuse_gathered(name_, "compute_forces"); }
  std::optional<parts::Fault> check() const override { refuse_gathered(name_, "check"); }
  void advance(Real, Real) override { refuse_gathered(name_, "advance"); }
  void finish_step(Real) override { refuse_gathered(name_, "finish_step"); }
  parts::Energies energies() const override { refuse_gathered(name_, "energies"); }

 private:
  std::string name_;
  const char* method_;
  parts::GatheredPoints<D> g_;
};

/// The parts `which` (indices, any order) gathered whole on the root, the others empty, at the
/// same indices as `parts` (collective: every rank passes the same `which`). Null on one rank,
/// where the parts are read as they are.
template <int D>
std::unique_ptr<std::vector<std::unique_ptr<parts::Part<D>>>> gathered_parts(
    const parallel::Comm& comm, const std::vector<std::unique_ptr<parts::Part<D>>>& parts,
    const std::vector<std::size_t>& which) {
  if (comm.size() == 1) return nullptr;
  auto out = std::make_unique<std::vector<std::unique_ptr<parts::Part<D>>>>();
  for (std::size_t k = 0; k < parts.size(); ++k) {
    parts::GatheredPoints<D> g;
    if (std::find(which.begin(), which.end(), k) != which.end()) {
      auto got = parts[k]->gathered_points();
      if (!got) throw std::logic_error("part '" + parts[k]->name() + "' is not spread");
      g = std::move(*got);
    }
    out->push_back(
        std::make_unique<GatheredPart<D>>(parts[k]->name(), parts[k]->method(), std::move(g)));
  }
  return out;
}

}  // namespace crater::solver
