// A tunnel lining's measurements; see lining_probe.hpp.
#include "solver/lining_probe.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string_view>

#include "core/index.hpp"
#include "fem/element_geometry.hpp"
#include "io/checkpoint/checkpoint.hpp"

namespace crater::solver {
namespace {

constexpr Real kNaN = std::numeric_limits<Real>::quiet_NaN();
constexpr std::array<const char*, 3> kGaugeNames{"crown", "springline", "invert"};

const fields::FieldView* field(const std::vector<fields::FieldView>& views, std::string_view name) {
  for (const auto& v : views)
    if (v.info->name == name) return &v;
  return nullptr;
}

}  // namespace

template <int D>
LiningProbe<D>::LiningProbe(const io::Config& c, const std::vector<std::unique_ptr<Part<D>>>& parts)
    : part_(*c.probes.lining) {
  for (const parts::Face f : c.domain.symmetry_planes) {
    (void)f;
    mirror_factor_ *= 2;
  }
  max_.fill(0);
  min_.fill(0);
  const Part<D>& lining = *parts[part_];
  const Geometry<D> g = lining.geometry();
  const auto* disp = field(lining.point_fields(), "displacement");
  const auto& xn = *g.points;
  const Index nn = static_cast<Index>(xn.size());
  auto ref = [&](Index i) {
    Vec<D> x = xn[at(i)];
    if (disp)
      for (int d = 0; d < D; ++d)
        x[d] -= disp->real_data[at(i) * D + static_cast<std::size_t>(d)];
    return x;
  };
  Vec<D> p = Vec<D>::Zero(), axis = Vec<D>::Zero();
  for (int d = 0; d < D; ++d)
    p[d] = c.probes.lining_axis_point_m[static_cast<std::size_t>(d)];
  if constexpr (D == 3)
    for (int d = 0; d < 3; ++d)
      axis[d] = c.probes.lining_axis_direction[static_cast<std::size_t>(d)];
  if (axis.norm() > 0) axis.normalize();
  // Per node: its offset from the axis (perpendicular) and its distance along it.
  std::vector<Vec<D>> off(at(nn));
  std::vector<Real> along(at(nn), 0);
  Real nearest_section = std::numeric_limits<Real>::infinity();
  for (Index i = 0; i < nn; ++i) {
    const Vec<D> r = ref(i) - p;
    along[at(i)] = r.dot(axis);
    off[at(i)] = r - along[at(i)] * axis;
    nearest_section = std::min(nearest_section, std::abs(along[at(i)]));
  }
  Real r_in = std::numeric_limits<Real>::infinity(), extent = 0;
  for (Index i = 0; i < nn; ++i) {
    extent = std::max(extent, off[at(i)].norm());
    if (std::abs(along[at(i)]) <= nearest_section + 1e-9 * (1 + extent))
      r_in = std::min(r_in, off[at(i)].norm());
  }
  // Across: the horizontal direction perpendicular to the axis, towards the side the model has.
  Vec<D> up = Vec<D>::Zero();
  up[D - 1] = 1;
  Vec<D> across = Vec<D>::Zero();
  if constexpr (D == 3) {
    across = axis.cross(up);
  } else {
    across[0] = 1;
  }
  if (across.norm() > 0) across.normalize();
  Real most = 0, least = 0;
  for (Index i = 0; i < nn; ++i) {
    const Real s = off[at(i)].dot(across);
    most = std::max(most, s);
    least = std::min(least, s);
  }
  if (most < -least) across = -across;
  std::array<Real, kGauges> score;
  score.fill(-std::numeric_limits<Real>::infinity());
  for (Index i = 0; i < nn; ++i) {
    if (std::abs(along[at(i)]) > nearest_section + 1e-9 * (1 + extent)) continue;
    if (off[at(i)].norm() > r_in * (1 + 1e-3)) continue;
    const std::array<Real, kGauges> s{off[at(i)].dot(up), off[at(i)].dot(across),
                                      -off[at(i)].dot(up)};
    for (int k = 0; k < kGauges; ++k)
      if (s[at(k)] > score[at(k)]) {
        score[at(k)] = s[at(k)];
        node_[at(k)] = i;
      }
  }
  for (int k = 0; k < kGauges; ++k)
    if (node_[at(k)] >= 0) {
      const Vec<D>& o = off[at(node_[at(k)])];
      outward_[at(k)] = o.norm() > 0 ? Vec<D>(o / o.norm()) : Vec<D>::Zero();
      x0_[at(k)] = ref(node_[at(k)]);
    }
  // Element volumes at t = 0.
  const Index ne = static_cast<Index>(g.offsets.size());
  volume0_.assign(at(ne), 0);
  for (Index e = 0; e < ne; ++e) {
    const std::int64_t first = e == 0 ? 0 : g.offsets[at(e - 1)];
    if (g.offsets[at(e)] - first != fem::kElementNodes<D>) continue;
    fem::NodeArray<D> xe;
    for (int k = 0; k < fem::kElementNodes<D>; ++k)
      xe[at(k)] = ref(static_cast<Index>(g.connectivity[at(first + k)]));
    volume0_[at(e)] = std::max(Real(0), fem::uniform_strain_gradients<D>(xe).volume);
  }
}

template <int D>
Real LiningProbe<D>::radial(const Part<D>& lining, int g) const {
  // The node alone, not the part's displacement field: this runs every step.
  const Index i = node_[at(g)];
  if (i < 0) return kNaN;
  const Vec<D> u = lining.points()[at(i)] - x0_[at(g)];
  Real r = 0;
  for (int d = 0; d < D; ++d)
    r += u[d] * outward_[at(g)][d];
  return r;
}

template <int D>
std::vector<std::string> LiningProbe<D>::history_columns() const {
  std::vector<std::string> out;
  for (const char* n : kGaugeNames)
    out.push_back(fmt::format("lining_{}_radial_m", n));
  return out;
}

template <int D>
std::vector<Real> LiningProbe<D>::history_values(
    const std::vector<std::unique_ptr<Part<D>>>& parts) const {
  std::vector<Real> out;
  for (int g = 0; g < kGauges; ++g)
    out.push_back(radial(*parts[part_], g));
  return out;
}

template <int D>
void LiningProbe<D>::after_step(const std::vector<std::unique_ptr<Part<D>>>& parts) {
  for (int g = 0; g < kGauges; ++g) {
    const Real u = radial(*parts[part_], g);
    if (!std::isfinite(u)) continue;
    max_[at(g)] = std::max(max_[at(g)], u);
    min_[at(g)] = std::min(min_[at(g)], u);
  }
}

template <int D>
void LiningProbe<D>::metrics(const std::vector<std::unique_ptr<Part<D>>>& parts,
                             std::vector<Diagnostic>& m) const {
  for (int g = 0; g < kGauges; ++g) {
    if (node_[at(g)] < 0) continue;
    m.push_back({fmt::format("lining_{}_displacement_max_m", kGaugeNames[at(g)]), max_[at(g)]});
    m.push_back({fmt::format("lining_{}_displacement_min_m", kGaugeNames[at(g)]), min_[at(g)]});
  }
  const auto cf = parts[part_]->cell_fields();
  const auto* damage = field(cf, "damage");
  const auto* eroded = field(cf, "eroded");
  Real dmax = 0, damaged = 0;
  Index eroded_count = 0;
  for (std::size_t e = 0; e < volume0_.size(); ++e) {
    const bool gone = eroded && eroded->integer_data[e] != 0;
    eroded_count += gone ? 1 : 0;
    const Real d = damage ? damage->real_data[e] : 0;
    if (!gone) dmax = std::max(dmax, d);
    if (d >= Real(0.5) || gone) damaged += volume0_[e];
  }
  const std::array<Diagnostic, 3> whole{
      Diagnostic{"lining_damage_max", dmax},
      Diagnostic{"lining_damaged_volume_m3", damaged * mirror_factor_},
      Diagnostic{"lining_eroded_elements", static_cast<Real>(eroded_count)}};
  m.insert(m.end(), whole.begin(), whole.end());
}

template <int D>
void LiningProbe<D>::save(parts::StateWriter& w) const {
  w.tag("lining_probe");
  for (int g = 0; g < kGauges; ++g) {
    w.value(max_[at(g)]);
    w.value(min_[at(g)]);
  }
}

template <int D>
void LiningProbe<D>::load(parts::StateReader& r) {
  r.tag("lining_probe");
  for (int g = 0; g < kGauges; ++g) {
    r.value(max_[at(g)]);
    r.value(min_[at(g)]);
  }
}

template class LiningProbe<2>;
template class LiningProbe<3>;

}  // namespace crater::solver
