// The cells of a contact zone; see contact_zone.hpp.
#include "contact/contact_zone.hpp"

#include "contact/face_search.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <span>

namespace crater::contact {

template <int D>
ZoneCells<D>::ZoneCells(Real reach_m) {
  usable_ = reach_m > 0 && std::isfinite(reach_m);
  // A point within the reach of a marked one lies in the next cell at most: the factor covers
  // the rounding of x / cell.
  cell_m_ = usable_ ? reach_m * (1 + Real(1e-9)) : 0;
}

template <int D>
typename ZoneCells<D>::Key ZoneCells<D>::key_of(const Vec<D>& x) const {
  Key k;
  for (int d = 0; d < D; ++d)
    k[at(d)] = static_cast<std::int64_t>(std::floor(x[d] / cell_m_));
  return k;
}

template <int D>
void ZoneCells<D>::occupy(const Vec<D>& x) {
  // Beyond 2^52 cells from the origin a key is not exact; such a point is far out of any domain.
  if (!usable_ || !x.allFinite() || (x.array().abs() / cell_m_).maxCoeff() > Real(1e15)) return;
  occupied_.push_back(key_of(x));
}

template <int D>
void ZoneCells<D>::seal(const parallel::Comm* comm) {
  std::sort(occupied_.begin(), occupied_.end());
  occupied_.erase(std::unique(occupied_.begin(), occupied_.end()), occupied_.end());
  if (comm && comm->size() > 1) {
    const auto bytes = comm->all_gather(std::as_bytes(std::span<const Key>(occupied_)));
    occupied_.resize(bytes.size() / sizeof(Key));
    if (!occupied_.empty()) std::memcpy(occupied_.data(), bytes.data(), bytes.size());
    std::sort(occupied_.begin(), occupied_.end());
    occupied_.erase(std::unique(occupied_.begin(), occupied_.end()), occupied_.end());
  }
  bitmap_.clear();
  dilated_.clear();
  dense_ = false;
  if (occupied_.empty()) return;
  Key lo = occupied_.front(), hi = occupied_.front();
  for (const Key& k : occupied_)
    for (int d = 0; d < D; ++d) {
      lo[at(d)] = std::min(lo[at(d)], k[at(d)] - 1);
      hi[at(d)] = std::max(hi[at(d)], k[at(d)] + 1);
    }
  constexpr std::int64_t kStencil = D == 2 ? 9 : 27;
  const std::int64_t budget = 64 * kStencil * static_cast<std::int64_t>(occupied_.size()) + 4096;
  std::int64_t cells = 1;
  for (int d = 0; d < D; ++d) {
    extent_[at(d)] = hi[at(d)] - lo[at(d)] + 1;
    cells = extent_[at(d)] > budget / cells ? budget + 1 : cells * extent_[at(d)];
  }
  lo_ = lo;
  dense_ = cells <= budget;
  // Every marked cell with its neighbours (the 3^D block about it).
  auto each_neighbour = [](const Key& k, auto&& f) {
    Key n;
    for (int m = 0; m < kStencil; ++m) {
      int rest = m;
      for (int d = 0; d < D; ++d) {
        n[at(d)] = k[at(d)] + rest % 3 - 1;
        rest /= 3;
      }
      f(n);
    }
  };
  if (dense_) {
    bitmap_.assign(static_cast<std::size_t>(cells), 0);
    for (const Key& k : occupied_)
      each_neighbour(k, [&](const Key& n) {
        std::int64_t i = 0;
        for (int d = D - 1; d >= 0; --d)
          i = i * extent_[at(d)] + (n[at(d)] - lo_[at(d)]);
        bitmap_[static_cast<std::size_t>(i)] = 1;
      });
    return;
  }
  dilated_.reserve(occupied_.size() * kStencil);
  for (const Key& k : occupied_)
    each_neighbour(k, [&](const Key& n) { dilated_.push_back(n); });
  std::sort(dilated_.begin(), dilated_.end());
  dilated_.erase(std::unique(dilated_.begin(), dilated_.end()), dilated_.end());
}

template <int D>
bool ZoneCells<D>::near(const Vec<D>& x) const {
  if (!x.allFinite()) return true;
  if (occupied_.empty()) return false;
  if ((x.array().abs() / cell_m_).maxCoeff() > Real(1e15)) return false;
  const Key k = key_of(x);
  if (!dense_) return std::binary_search(dilated_.begin(), dilated_.end(), k);
  std::int64_t i = 0;
  for (int d = D - 1; d >= 0; --d) {
    const std::int64_t o = k[at(d)] - lo_[at(d)];
    if (o < 0 || o >= extent_[at(d)]) return false;
    i = i * extent_[at(d)] + o;
  }
  return bitmap_[static_cast<std::size_t>(i)] != 0;
}

template <int D>
bool ZoneCells<D>::marks(const Vec<D>& x) const {
  if (!usable_ || !x.allFinite() || (x.array().abs() / cell_m_).maxCoeff() > Real(1e15))
    return false;
  return std::binary_search(occupied_.begin(), occupied_.end(), key_of(x));
}

template <int D>
bool faces_in_marked_cells(const parts::ContactSurface<D>& surface,
                           const std::vector<Vec<D>>& node_position, const ZoneCells<D>& cells) {
  parts::ContactSurface<D> then = surface;
  then.node_position = &node_position;
  const FaceCentres<D> c = face_centres(then);
  return std::all_of(c.centre.begin(), c.centre.end(),
                     [&](const Vec<D>& x) { return cells.marks(x); });
}

template class ZoneCells<2>;
template class ZoneCells<3>;
template bool faces_in_marked_cells<2>(const parts::ContactSurface<2>&, const std::vector<Vec<2>>&,
                                       const ZoneCells<2>&);
template bool faces_in_marked_cells<3>(const parts::ContactSurface<3>&, const std::vector<Vec<3>>&,
                                       const ZoneCells<3>&);

}  // namespace crater::contact
