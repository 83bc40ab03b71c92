// A contact restricted to a group of a solid's mesh ([[contacts]] surface_groups): the contact
// sees only the faces of the part's surface whose nodes all belong to the group, and so only
// those nodes (a tunnel's lining against the soil by lining_outer and soil_inner, not by the
// lining's inner wall or the soil's far faces). Faces a later erosion exposes count when
// their nodes are in the group. Without a group the surface is the part's own.
//
// The selection is kept while the surface's revision holds (it changes when faces do); each
// call gathers the selected faces' stiffness, which changes every step: work in proportion to
// the group's faces, not the surface's.
#pragma once

#include <array>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "core/index.hpp"
#include "core/types.hpp"
#include "parts/part.hpp"

namespace crater::contact {

template <int D>
class SurfaceFilter {
 public:
  /// No restriction.
  SurfaceFilter() = default;
  /// The faces of a surface over `node_count` nodes whose nodes are all in `group_nodes`.
  SurfaceFilter(const std::vector<Index>& group_nodes, std::size_t node_count)
      : active_(true), in_group_(node_count, 0) {
    for (const Index n : group_nodes) {
      if (n < 0 || static_cast<std::size_t>(n) >= node_count)
        throw std::logic_error("contact surface group: a node outside the part");
      in_group_[at(n)] = 1;
    }
  }

  bool active() const { return active_; }

  /// The surface as the contact sees it: `full`, or a view of its faces in the group (valid
  /// until the next call, or the part's next stage). Face indices are the view's own.
  parts::ContactSurface<D> view(const parts::ContactSurface<D>& full) const {
    if (!active_) return full;
    if (!built_ || revision_ != full.revision) select(full);
    stiffness_.resize(selected_.size());
    for (std::size_t k = 0; k < selected_.size(); ++k)
      stiffness_[k] = (*full.face_stiffness)[at(selected_[k])];
    parts::ContactSurface<D> s = full;
    s.faces = &faces_;
    s.face_element = &face_element_;
    s.face_stiffness = &stiffness_;
    return s;
  }

 private:
  void select(const parts::ContactSurface<D>& full) const {
    selected_.clear();
    faces_.clear();
    face_element_.clear();
    const auto& faces = *full.faces;
    for (std::size_t f = 0; f < faces.size(); ++f) {
      bool in = true;
      for (const Index n : faces[f])
        in = in && static_cast<std::size_t>(n) < in_group_.size() && in_group_[at(n)] != 0;
      if (!in) continue;
      selected_.push_back(static_cast<Index>(f));
      faces_.push_back(faces[f]);
      face_element_.push_back((*full.face_element)[f]);
    }
    revision_ = full.revision;
    built_ = true;
  }

  bool active_ = false;
  std::vector<char> in_group_;  // per node of the part
  mutable bool built_ = false;
  mutable std::uint64_t revision_ = 0;
  mutable std::vector<Index> selected_;  // indices into the full surface's faces
  mutable std::vector<std::array<Index, parts::kFaceNodes<D>>> faces_;
  mutable std::vector<Index> face_element_;
  mutable std::vector<Real> stiffness_;
};

}  // namespace crater::contact
