// [[gauges]]: history output at chosen entities (LS-DYNA's *DATABASE_HISTORY_NODE and _SOLID).
// Each gauge reads output fields of one part at nodes, particles or elements, chosen by id or as
// the ones nearest a point at t = 0, and the run writes them to gauges.csv: a row every
// output.gauges_every_steps steps, at every frame and at the end, one column per gauge, entity,
// field and component. The values are the ones the part's VTU frame of the same step holds
// (Part::point_fields, cell_fields). A particle (SPH, DEM) is followed by its `id` field, which
// stays with it when others leave the domain; one that has left gives NaN. A sum (`sum`, or an
// FEM `face`: the nodes on that face of the part's bounding box at t = 0) writes one value per
// field and component, summed over the entities in their order (the resultant of a force field).
//
// Cost: a row reads each gauged part's field views once; on several ranks each rank reads its
// own entities and sends the gauged ones' values to the root (one gather of a few records). Stored
// fields (SPH, DEM, FEM nodal velocity) are views; an FEM part's derived fields (displacement, von
// Mises, pressure, density) are evaluated over the part for the view, as for a frame: hence the
// cadence.
#pragma once

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "io/scenario/config.hpp"
#include "parallel/comm.hpp"
#include "parts/part.hpp"

namespace crater::solver {

template <int D>
class Gauges {
 public:
  using PartList = std::vector<std::unique_ptr<parts::Part<D>>>;

  /// Resolves every gauge on the parts as built (t = 0): its fields (InputError naming the
  /// part's fields for an unknown one) and its entities (InputError for an id out of range).
  Gauges(const io::Config& c, const PartList& parts);

  bool empty() const { return columns_.empty(); }
  /// "step,time_s,<columns>\n".
  std::string header() const;
  /// One row of values at this step. On several ranks (`comm`; collective) each rank reads
  /// the gauged entities it owns and the root writes the row (empty on the other ranks).
  std::string row(Index step, Real t_s, const PartList& parts,
                  const parallel::Comm* comm = nullptr) const;

 private:
  // One field of one gauge at its entities.
  struct Read {
    std::size_t part = 0;
    std::string field;
    bool cell = false;            // an element field
    bool by_particle_id = false;  // entities are ids of the part's `id` field
    std::vector<std::int64_t> entities;
    int components = 1;
    bool sum = false;  // one value per component: the sum over the entities, in their order
  };
  std::vector<Real> values_of(const Read& r, const fields::FieldView* v,
                              const fields::FieldView* ids) const;
  std::string row_on_ranks(Index step, Real t_s, const PartList& parts,
                           const parallel::Comm& comm) const;
  std::string formatted(Index step, Real t_s, const std::vector<std::vector<Real>>& values) const;
  // Columns stem, or stem_x, _y, ... (stem_xx, ... for a tensor).
  void add_columns(const std::string& stem, int components);

  std::vector<Read> reads_;
  std::vector<std::string> columns_;
};

}  // namespace crater::solver
