// A part spread over ranks (Part::distribute, issue 29) written as one: its points and point
// fields, and a mesh part's cells and cell fields, gathered from every rank and ordered by the
// entities' global ids, so that a frame has the same bits on any rank count
// (docs/distributed.md, "crater run on ranks").
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <iterator>
#include <numeric>
#include <span>
#include <vector>

#include "core/types.hpp"
#include "fields/field_set.hpp"
#include "parallel/comm.hpp"

namespace crater::parts {

/// Fields of entities gathered from every rank, in ascending id.
struct GatheredFields {
  Index count = 0;  // entities
  std::vector<fields::FieldInfo> infos;
  std::vector<int> components;
  std::vector<std::uint8_t> integer;                // per field: its values are integers
  std::vector<std::vector<Real>> reals;             // per field (empty for integer fields)
  std::vector<std::vector<std::int64_t>> integers;  // per field (empty for real fields)

  /// Views over the fields, as Part::point_fields gives them.
  std::vector<fields::FieldView> views() const {
    std::vector<fields::FieldView> v;
    for (std::size_t k = 0; k < infos.size(); ++k) {
      const bool is_int = integer[k] != 0;
      v.push_back(fields::FieldView{&infos[k], components[k], is_int,
                                    is_int ? nullptr : reals[k].data(),
                                    is_int ? integers[k].data() : nullptr, count});
    }
    return v;
  }
};

/// A spread part's local entities by their numbers in the whole part (Part::own_numbers): per
/// local point and per local cell, -1 for a ghost.
struct OwnNumbers {
  std::vector<std::int64_t> point, cell;
};

/// The numbers `id` of a part's local entities, -1 where ghost(i).
template <class Ghost>
std::vector<std::int64_t> own_numbers_of(std::span<const std::int64_t> id, Ghost&& ghost) {
  std::vector<std::int64_t> n(id.begin(), id.end());
  for (std::size_t i = 0; i < n.size(); ++i)
    if (ghost(static_cast<Index>(i))) n[i] = -1;
  return n;
}

/// The gathered frame of a part: points and point fields in ascending id; for a mesh part also
/// its cells (VTK connectivity over the points, offsets, cell types) and cell fields in
/// ascending element id (empty for particles).
template <int D>
struct GatheredPoints {
  std::vector<Vec<D>> points;
  GatheredFields point;
  std::vector<std::int64_t> connectivity, offsets;
  std::vector<std::uint8_t> cell_types;
  GatheredFields cell;

  std::vector<fields::FieldView> views() const { return point.views(); }
};

/// Gathers the entities i of this rank with keep(i) (its own, not its ghosts): every view's
/// values with id[i], from every rank to the root, ordered by id. Collective; on the other ranks
/// the result is empty. Every rank must pass the same fields in the same order.
template <class Keep>
GatheredFields gather_fields(const parallel::Comm& comm, std::span<const std::int64_t> id,
                             const std::vector<fields::FieldView>& views, Keep&& keep) {
  std::size_t words = 1;  // id (its bits), then every field's components
  for (const auto& v : views)
    words += static_cast<std::size_t>(v.components);
  std::vector<Real> mine;
  for (std::size_t i = 0; i < id.size(); ++i) {
    if (!keep(static_cast<Index>(i))) continue;
    Real bits;
    std::memcpy(&bits, &id[i], sizeof bits);
    mine.push_back(bits);
    for (const auto& v : views)
      for (int c = 0; c < v.components; ++c) {
        const std::size_t at =
            i * static_cast<std::size_t>(v.components) + static_cast<std::size_t>(c);
        if (v.is_integer)
          std::memcpy(&bits, &v.integer_data[at], sizeof bits);
        else
          bits = v.real_data[at];
        mine.push_back(bits);
      }
  }
  // The root alone receives them (one piece per rank, PVTU, would spare it the whole part).
  const std::vector<Real> all = parallel::gather(comm, std::span<const Real>(mine));
  GatheredFields g;
  if (!comm.root()) return g;
  const std::size_t n = all.size() / words;
  auto id_of = [&](std::size_t e) {
    std::int64_t k;
    std::memcpy(&k, &all[e * words], sizeof k);
    return k;
  };
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return id_of(a) < id_of(b); });
  g.count = static_cast<Index>(n);
  for (const auto& v : views) {
    g.infos.push_back(*v.info);
    g.components.push_back(v.components);
    g.integer.push_back(v.is_integer ? 1 : 0);
    const std::size_t size = n * static_cast<std::size_t>(v.components);
    g.reals.emplace_back(v.is_integer ? 0 : size);
    g.integers.emplace_back(v.is_integer ? size : 0);
  }
  for (std::size_t q = 0; q < n; ++q) {
    const Real* e = &all[order[q] * words + 1];
    for (std::size_t k = 0; k < views.size(); ++k) {
      const auto c = static_cast<std::size_t>(views[k].components);
      for (std::size_t j = 0; j < c; ++j, ++e) {
        if (views[k].is_integer)
          std::memcpy(&g.integers[k][q * c + j], e, sizeof(Real));
        else
          g.reals[k][q * c + j] = *e;
      }
    }
  }
  return g;
}

/// gather_fields with the positions x: the points and their fields, ordered by id, on the root.
template <int D, class Keep>
GatheredPoints<D> gather_points(const parallel::Comm& comm, std::span<const std::int64_t> id,
                                std::span<const Vec<D>> x,
                                const std::vector<fields::FieldView>& views, Keep&& keep) {
  static const fields::FieldInfo kPosition{"position", "m", fields::kNone};
  std::vector<fields::FieldView> with_x = {
      fields::FieldView{&kPosition, D, false, x.empty() ? nullptr : x.front().data(), nullptr,
                        static_cast<Index>(x.size())}};
  with_x.insert(with_x.end(), views.begin(), views.end());
  GatheredFields all = gather_fields(comm, id, with_x, keep);
  GatheredPoints<D> g;
  if (!comm.root()) return g;
  g.points.resize(static_cast<std::size_t>(all.count));
  for (std::size_t q = 0; q < g.points.size(); ++q)
    for (int d = 0; d < D; ++d)
      g.points[q][d] = all.reals[0][q * D + static_cast<std::size_t>(d)];
  g.point.count = all.count;
  g.point.infos.assign(all.infos.begin() + 1, all.infos.end());
  g.point.components.assign(all.components.begin() + 1, all.components.end());
  g.point.integer.assign(all.integer.begin() + 1, all.integer.end());
  g.point.reals.assign(std::make_move_iterator(all.reals.begin() + 1),
                       std::make_move_iterator(all.reals.end()));
  g.point.integers.assign(std::make_move_iterator(all.integers.begin() + 1),
                          std::make_move_iterator(all.integers.end()));
  return g;
}

/// The entries `rows` (local indices, in that order) of every view: a piece of a frame written by
/// the rank that holds them (output.pieces = "ranks"; no communication).
inline GatheredFields select_fields(const std::vector<fields::FieldView>& views,
                                    const std::vector<Index>& rows) {
  GatheredFields g;
  g.count = static_cast<Index>(rows.size());
  for (const auto& v : views) {
    g.infos.push_back(*v.info);
    g.components.push_back(v.components);
    g.integer.push_back(v.is_integer ? 1 : 0);
    const auto c = static_cast<std::size_t>(v.components);
    std::vector<Real> reals(v.is_integer ? 0 : rows.size() * c);
    std::vector<std::int64_t> integers(v.is_integer ? rows.size() * c : 0);
    for (std::size_t q = 0; q < rows.size(); ++q)
      for (std::size_t j = 0; j < c; ++j) {
        const std::size_t from = static_cast<std::size_t>(rows[q]) * c + j;
        if (v.is_integer)
          integers[q * c + j] = v.integer_data[from];
        else
          reals[q * c + j] = v.real_data[from];
      }
    g.reals.push_back(std::move(reals));
    g.integers.push_back(std::move(integers));
  }
  return g;
}

/// This rank's entities i with keep(i) (its own, not its ghosts), in local order, as its piece
/// of a frame: their points and point fields (no communication).
template <int D, class Keep>
GatheredPoints<D> piece_points(std::span<const Vec<D>> x,
                               const std::vector<fields::FieldView>& views, Keep&& keep) {
  std::vector<Index> rows;
  for (std::size_t i = 0; i < x.size(); ++i)
    if (keep(static_cast<Index>(i))) rows.push_back(static_cast<Index>(i));
  GatheredPoints<D> g;
  g.points.reserve(rows.size());
  for (const Index i : rows)
    g.points.push_back(x[static_cast<std::size_t>(i)]);
  g.point = select_fields(views, rows);
  return g;
}

}  // namespace crater::parts
