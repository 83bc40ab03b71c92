// The SPH part on several ranks (issue 29, docs/distributed.md, "The SPH part on ranks").
//
// Each rank owns the particles of its box of a recursive coordinate bisection (the cuts made
// once, from the whole part, fields::Spread) and holds, beside them, copies of the other ranks'
// particles within the lists' reach of its own (ghosts; twice that with wall particles, whose
// state averages their own fluid neighbours), in the same arrays. Owned particles and ghosts are
// sorted together in the canonical order (a cell order by the lists' reach, ids breaking ties),
// so every list row, and every sum of a particle's rates, runs over the same neighbours in the
// same order as on one rank. Ghosts are never integrated nor summed: their state (kHalo fields:
// position, velocity, mass, density, energy, h, burn, Omega) comes from their owners at the start
// of every force stage and, with the summation density, again after it; the EOS is evaluated on
// them. At each rebuild of the lists (a global decision) particles move to the rank whose box
// now holds them and the ghosts are made anew.
#include <cstdint>
#include <cstring>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "parts/on_ranks.hpp"
#include "sph/kernels.hpp"
#include "sph/sph_part_impl.hpp"

namespace crater::sph::detail {

template <int D>
void SphPart<D>::distribute(const parallel::Comm& comm) {
  ++state_epoch_;
  if (spread_.active()) throw std::logic_error("sph: distribute() twice");
  if (skin_.radius() > 0 && skin_.positions().size() == static_cast<std::size_t>(f_.size())) {
    spread_ = fields::Spread<D>();
    const std::vector<Vec<D>> kept =
        spread_.restore(comm, f_, skin_.positions(), id_, halo_reach(skin_.radius()));
    skin_ = skin_.with_positions(kept);
    if (!comm.root()) {  // the whole part's, held by the root
      reflections_ = 0;
      external_work_ = 0;
    }
    build_lists();
    return;
  }
  spread_.start(comm, f_, x_);
  skin_.invalidate();  // the first force stage builds the lists, and the ghosts
}

template <int D>
Index SphPart<D>::count() const {
  if (!spread_.active()) return f_.size();
  return static_cast<Index>(
      spread_.comm().sum(static_cast<std::int64_t>(spread_.owned(f_.size()))));
}

template <int D>
std::optional<parts::GatheredPoints<D>> SphPart<D>::gathered_points() const {
  if (!spread_.active()) return std::nullopt;
  return parts::gather_points<D>(spread_.comm(), std::span<const std::int64_t>(id_),
                                 std::span<const Vec<D>>(x_), point_fields(),
                                 [&](Index i) { return !ghost(i); });
}

template <int D>
std::optional<parts::OwnNumbers> SphPart<D>::own_numbers() const {
  if (!spread_.active()) return std::nullopt;
  parts::OwnNumbers n;
  n.point =
      parts::own_numbers_of(std::span<const std::int64_t>(id_), [&](Index i) { return ghost(i); });
  return n;
}

template <int D>
std::optional<parts::GatheredPoints<D>> SphPart<D>::own_piece() const {
  if (!spread_.active()) return std::nullopt;
  return parts::piece_points<D>(std::span<const Vec<D>>(x_), point_fields(),
                                [&](Index i) { return !ghost(i); });
}

// The particles each rank owns (fewest, most) and the ghosts it holds (mean, most), the bytes of
// one refresh of the ghosts' state summed over the ranks, how often the cuts were made again, and
// how many particles moved to another rank (arrivals summed over the ranks).
template <int D>
std::vector<parts::Diagnostic> SphPart<D>::rank_figures() const {
  if (!spread_.active()) return {};
  const parallel::Comm& comm = spread_.comm();
  const auto owned = static_cast<Real>(spread_.owned(f_.size()));
  const Index ghosts = spread_.ghosts();
  const auto all_ghosts = static_cast<Real>(comm.sum(static_cast<std::int64_t>(ghosts)));
  return {
      {"owned_min", comm.min(owned)},
      {"owned_max", comm.max(owned)},
      {"ghosts_mean", all_ghosts / static_cast<Real>(comm.size())},
      {"ghosts_max", comm.max(static_cast<Real>(ghosts))},
      {"ghost_refresh_bytes_per_step",
       all_ghosts * static_cast<Real>(f_.packed_bytes(fields::kHalo)) * (summation() ? 2 : 1)},
      {"rebalances", static_cast<Real>(spread_.rebalances())},
      {"load_ratio", spread_.load_ratio()},
      {"migrations", static_cast<Real>(comm.sum(static_cast<std::int64_t>(spread_.arrivals())))}};
}

// A checkpoint on ranks: every rank sends its particles (every field, and where each was when the
// lists were built) to the root, which writes the whole part in the order one rank holds it: the
// cell order of the positions at that build by the lists' reach, ids breaking ties (relist). The
// file is that of a run on one rank, byte for byte, and resumes there or on any rank count.
template <int D>
void SphPart<D>::save_gathered(parts::StateWriter& w) const {
  const parallel::Comm& comm = spread_.comm();
  const auto [owned, built] =
      parts::owned_at_build<D>(f_.size(), skin_.positions(), [&](Index i) { return ghost(i); });
  std::vector<std::byte> mine;
  f_.pack(owned, fields::kEveryField, mine);
  std::vector<std::int64_t> bytes;
  const std::vector<std::byte> all = comm.gather(mine, &bytes);
  const std::vector<Real> all_built = parallel::gather(comm, std::span<const Real>(built));
  const Index reflections = all_reflections();
  const Real penetration = global_max(max_penetration_);
  std::vector<Real> wall_rho =
      wall_complete_.empty() ? wall_.rho : shared_wall_density();  // collective
  if (!comm.root()) return;                                        // the root writes
  fields::FieldSet<D> whole = f_;
  whole.resize(0);
  std::size_t from = 0;
  for (const std::int64_t b : bytes) {  // each rank's particles, field after field
    whole.unpack_append(std::span<const std::byte>(all).subspan(from, static_cast<std::size_t>(b)),
                        fields::kEveryField);
    from += static_cast<std::size_t>(b);
  }
  auto [order, sorted] =
      parts::order_of_one_rank<D>(whole, std::span<const Real>(all_built), skin_.radius());
  whole.permute(order);
  const neighbors::VerletSkin<D> skin = skin_.with_positions(std::move(sorted));
  archive(w, *this, whole, skin, reflections, penetration, wall_rho);
}

// A wall particle within the lists' reach R of the box of this rank's own particles (at the
// build) has every fluid particle of its list here: each lies within R of it, so within 2 R of
// the box, the halo's reach with walls (halo_reach). xb: the positions of the build.
template <int D>
void SphPart<D>::mark_complete_walls(std::span<const Vec<D>> xb, Real radius) {
  fields::Box<D> own;
  for (Index i = 0; i < f_.size(); ++i)
    if (!ghost(i)) own.add(xb[at(i)]);
  wall_complete_.assign(wall_x_.size(), 0);
  if (own.empty()) return;
  const Real r2 = radius * radius;
  parallel::for_each(static_cast<Index>(wall_x_.size()), [&](Index w) {
    wall_complete_[at(w)] = own.distance2(wall_x_[at(w)]) <= r2 ? 1 : 0;
  });
}

// Every rank sends the densities of its complete wall particles; a wall particle complete on
// several ranks has the same bits on each (their lists and the fluid's state are one rank's), a
// wall particle complete on none has had no fluid in reach since the last build anywhere, and
// keeps the density every rank has. One all-gather at a rebuild (or a checkpoint).
template <int D>
std::vector<Real> SphPart<D>::shared_wall_density() const {
  struct Entry {
    std::int64_t w;
    Real rho;
  };
  std::vector<Entry> mine;
  for (std::size_t w = 0; w < wall_complete_.size(); ++w)
    if (wall_complete_[w]) mine.push_back({static_cast<std::int64_t>(w), wall_.rho[w]});
  const std::vector<Entry> all = parallel::all_gather(spread_.comm(), std::span<const Entry>(mine));
  std::vector<Real> rho = wall_.rho;
  std::vector<std::uint8_t> seen(rho.size(), 0);
  for (const Entry& e : all) {
    if (seen[at(e.w)] && std::memcmp(&rho[at(e.w)], &e.rho, sizeof(Real)) != 0)
      throw std::logic_error("sph: a wall particle averaged differently on two ranks");
    rho[at(e.w)] = e.rho;
    seen[at(e.w)] = 1;
  }
  return rho;
}

// The contacts with other parts on ranks see the whole part in the order one rank holds it
// (contact/spread_coupling.hpp), as its checkpoints do.
template <int D>
const parts::WholeLayout* SphPart<D>::contact_layout() const {
  if (!spread_.active()) return nullptr;
  // The same until the particles are sorted and spread again, at the next build of the lists.
  if (contact_layout_builds_ == skin_.builds()) return &contact_layout_;
  contact_layout_ = parts::particle_layout<D>(spread_.comm(), std::span<const std::int64_t>(id_),
                                              skin_.positions(), skin_.radius(),
                                              [&](Index i) { return !ghost(i); });
  contact_layout_builds_ = skin_.builds();
  return &contact_layout_;
}

#define CRATER_SPH_RANKS(D)                                                             \
  template const parts::WholeLayout* SphPart<D>::contact_layout() const;                \
  template void SphPart<D>::distribute(const parallel::Comm&);                          \
  template Index SphPart<D>::count() const;                                             \
  template std::optional<parts::GatheredPoints<D>> SphPart<D>::gathered_points() const; \
  template std::optional<parts::GatheredPoints<D>> SphPart<D>::own_piece() const;       \
  template std::optional<parts::OwnNumbers> SphPart<D>::own_numbers() const;            \
  template std::vector<parts::Diagnostic> SphPart<D>::rank_figures() const;             \
  template void SphPart<D>::save_gathered(parts::StateWriter&) const;                   \
  template void SphPart<D>::mark_complete_walls(std::span<const Vec<D>>, Real);         \
  template std::vector<Real> SphPart<D>::shared_wall_density() const;
CRATER_SPH_RANKS(2)
CRATER_SPH_RANKS(3)
#undef CRATER_SPH_RANKS

}  // namespace crater::sph::detail
