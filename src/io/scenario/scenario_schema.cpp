// Every key of a scenario file. Adding a key: one entry here (docs follow from it), one field in
// Config, one line in the builder (docs/architecture.md, "How to add"). A material law's keys
// are its entry in material_laws.cpp.
#include <fmt/format.h>
#include <algorithm>

#include "io/scenario/material_laws.hpp"
#include "io/scenario/schema.hpp"
#include "io/scenario/schema_keys.hpp"

namespace crater::io {
namespace {

using namespace keys;

TableSchema make_scenario() {
  TableSchema t{"scenario", "What the run is.", {}, {}, {}};
  t.keys = {
      required(text("name", "Short name of the scenario; written to summary.json.")),
      with_default(text("description", "Free text shown by `crater check` and in the report."),
                   "\"\""),
      with_default(
          at_most(at_least(whole("dimension", "2 (plane strain, per metre of depth) or 3."), 2), 3),
          "2"),
      required(positive(real("end_time_s", "s", "Simulated time at which the run stops."))),
  };
  return t;
}

TableSchema make_time() {
  TableSchema t{"time", "The explicit time step.", {}, {}, {}};
  t.keys = {
      with_default(
          at_most(positive(real("safety_factor", "1",
                                "Global step = safety_factor x the smallest stable step of "
                                "all parts.")),
                  1.0),
          "0.9"),
      positive(real("fixed_dt_s", "s",
                    "Use this step instead of the computed one. Rejected if it exceeds the "
                    "stable step (the limiting part is named). Unset: computed every step.")),
      positive(real("min_dt_s", "s",
                    "Stop the run (exit 3, the last state written, the part and entity that "
                    "limit the step named) when the step falls below this: an element or "
                    "particle that collapses would otherwise hold the whole run at a crawl "
                    "(LS-DYNA's TSMIN). With multi_rate: the finest part's step. Unset: never.")),
      with_default(at_least(whole("max_steps", "Stop after this many steps (0: no limit)."), 0),
                   "0"),
      with_default(flag("multi_rate",
                        "Each part at its own stable step (docs/theory.md, \"Multi-rate "
                        "stepping\"): parts step in power-of-two multiples of the smallest "
                        "step, in cycles that end together; contacts are evaluated at the "
                        "finer of their two parts' steps. A step (history.csv, max_steps, "
                        "checkpoint_every_steps) is then one cycle. Not with fixed_dt_s."),
                   "false"),
      with_default(at_most(at_least(whole("multi_rate_max_ratio",
                                          "Multi-rate: the largest ratio of a part's step to "
                                          "the smallest (a power of two; 1: one step for all, "
                                          "in multi-rate's bookkeeping)."),
                                    1),
                           1024),
                   "8"),
      with_default(at_least(real("energy_warn_error", "1",
                                 "Energy guard: warn once when the relative energy balance "
                                 "error (history.csv energy_error, checked at every history "
                                 "row) exceeds this; 0: never."),
                            0),
                   "0.02"),
      with_default(at_least(real("energy_stop_error", "1",
                                 "Energy guard: stop the run (exit 3, the last state written, "
                                 "the part whose energy grew most named) when the relative "
                                 "energy balance error exceeds this; 0: never."),
                            0),
                   "0.2"),
  };
  return t;
}

TableSchema make_output() {
  TableSchema t{"output", "What is written to the run directory.", {}, {}, {}};
  t.keys = {
      positive(
          real("interval_s", "s", "Simulated time between VTU frames. Unset: end_time_s / 20.")),
      with_default(
          at_least(whole("history_every", "Write a history.csv row every this many steps."), 1),
          "10"),
      with_default(flag("vtu", "Write VTU/PVD files."), "true"),
      with_default(choice("vtu_encoding", {"appended", "base64"},
                          "VTU data layout: raw appended binary (smallest, fastest) or inline "
                          "base64."),
                   "\"appended\""),
      with_default(choice("pieces", {"gathered", "ranks"},
                          "On several MPI ranks: \"gathered\", one VTU per part and frame written "
                          "by rank 0 with every entity in id order (the file one rank writes); "
                          "\"ranks\", each rank writes its own entities as a piece "
                          "(pieces/<part>_<frame>_<rank>.vtu) and rank 0 a PVTU over them "
                          "(<part>_<frame>.pvtu, in the PVD), so that no rank holds a whole "
                          "part. On one rank: one VTU either way."),
                   "\"gathered\""),
      with_default(at_least(whole("checkpoint_every_steps",
                                  "Write a checkpoint (<out>/checkpoints/) every this "
                                  "many steps; 0: not by step count. A run resumes "
                                  "from one with `crater run SCENARIO --resume DIR`."),
                            0),
                   "0"),
      with_default(at_least(real("checkpoint_every_s", "s",
                                 "Also write a checkpoint after this much wall-clock time since "
                                 "the last one; 0: not by time. SIGINT and SIGTERM always "
                                 "write one."),
                            0),
                   "120"),
      with_default(
          at_least(whole("checkpoint_keep", "Newest checkpoints kept; older ones are deleted."), 1),
          "2"),
      at_least(whole("gauges_every_steps",
                     "Write a gauges.csv row ([[gauges]]) every this many steps, and at every "
                     "frame and the end. Unset: history_every."),
               1),
      with_default(flag("checkpoint_at_end",
                        "Write a checkpoint of the last state when the run stops at its end "
                        "time or time.max_steps (like LS-DYNA's end-of-run restart dump): `crater "
                        "run --resume DIR --set scenario.end_time_s=LATER` extends the run, "
                        "bit for bit the same as one run to the later time when the earlier end "
                        "time is an output time (a multiple of interval_s)."),
                   "true"),
      with_default(at_least(whole("max_frames",
                                  "Most VTU frames a run may write (end_time_s / "
                                  "interval_s + 1); more is refused as a likely "
                                  "mistake in interval_s."),
                            1),
                   "10000"),
      with_default(positive(real("max_bytes", "B",
                                 "Most bytes of VTU frames a run may write (frames x the "
                                 "size of one frame, known once the parts are built); more is "
                                 "refused by check and run. The free space of the disk is "
                                 "checked as well.")),
                   "50e9"),
      with_default(at_most(positive(real("memory_limit_fraction", "1",
                                         "Check and run refuse a scenario whose memory "
                                         "estimate (printed by `crater check`) exceeds this "
                                         "fraction of the memory available (MemAvailable, or "
                                         "the cgroup's limit), naming the parts and keys that "
                                         "make it too big.")),
                           1.0),
                   "0.8"),
  };
  return t;
}

TableSchema make_domain() {
  TableSchema t{"domain",
                "The box every entity must stay in. A particle leaving it stops the run "
                "(exit 3), unless `outflow = \"remove\"`. A scenario of FEM parts only may "
                "leave min_m and max_m (or the whole table) out: nothing then bounds it.",
                {},
                {},
                {}};
  t.keys = {
      vec("min_m", "m",
          "Lower corner. Required with SPH or DEM parts, symmetry planes, layer regions and "
          "the soil probes; unset (with max_m) only in an FEM-only scenario."),
      vec("max_m", "m", "Upper corner; each component above min_m. Required with min_m."),
      vec("gravity_m_s2", "m/s^2", "Gravitational acceleration. Unset: zero (no gravity)."),
      with_default(
          choice("outflow", {"stop", "remove"},
                 "What happens to an SPH or DEM particle whose centre leaves the box. "
                 "\"stop\": the run stops (exit 3), naming the particle. \"remove\": the "
                 "particle is deleted at the end of the step it left in (DEM grains: in "
                 "batches, see outflow_batch_steps; its velocity that of the step's end), as "
                 "hydrocodes deactivate material that leaves the mesh (detonation products "
                 "venting through a crater). What it carried is booked "
                 "in its part: its kinetic energy (plus internal m e for SPH, rotational for "
                 "DEM, and the energy stored in the DEM contacts and bonds it had) goes to "
                 "`eroded_j` of history.csv and summary.json, so the energy balance still "
                 "closes; the count and mass that left are the part's diagnostics "
                 "`left_domain_count` and `left_domain_mass_kg` in summary.json, and the "
                 "part's `count` and `mass_kg` are what stays. The remaining particles keep "
                 "their order, so results do not depend on the thread count, and restarts "
                 "stay bit-identical. A non-finite position is still a numerical failure. "
                 "FEM parts are not affected (they are not held to the box)."),
          "\"stop\""),
      with_default(
          at_least(whole("outflow_batch_steps",
                         "DEM grains that leave (outflow = \"remove\", or through transmitting "
                         "absorbing walls) are removed together, this many steps after the "
                         "first of a batch went out, and at every output frame: each removal "
                         "rebuilds the grains' neighbour lists, and in a blast a grain leaves "
                         "almost every step (the paper scenes set 32). Until then a grain that "
                         "went out moves on beyond the face and keeps its contacts, which "
                         "changes slow flows: a heap drained off a plate keeps 2 % fewer "
                         "spheres with 32. 1: at the end of the step it left in."),
                   1),
          "1"),
      with_default(
          choice("balance", {"time", "count"},
                 "On several MPI ranks (docs/distributed.md, \"The decomposition\"): what "
                 "a DEM or SPH part's cuts weigh when they are made again at a rebuild of its "
                 "lists. \"time\": each rank's measured compute time for the part since its "
                 "cuts were last made (its stages, less the time in MPI's calls, and a share "
                 "of the contacts' when its contact view is a zone), over windows of at least "
                 "100 steps; each grain or particle then weighs its model weight (below) times "
                 "its rank's time per unit of it. "
                 "\"count\": the cost model alone, a grain weighs 1 and an SPH particle 1 + "
                 "its pairs. The cuts are made again when the busiest rank exceeds the mean by "
                 "10 %. Either way the results are the "
                 "same bits (the cuts decide only which rank computes what); by time the cuts "
                 "follow the machine's clock and may differ from run to run. On one rank: "
                 "nothing."),
          "\"time\""),
      with_default(
          choice_list(
              "symmetry_planes", {"left", "right", "bottom", "top", "back", "front"},
              "Domain faces that are planes of symmetry for every part, so that half a "
              "symmetric problem is modelled (a quarter with two, an eighth with three): "
              "SPH parts get mirror images behind the face (as free-slip walls: exact), and "
              "an SPH part's region may reach across the plane (a quarter model's charge is "
              "the whole sphere centred on the planes): its lattice is laid from the plane, "
              "half a spacing off it, on the domain's side only; DEM "
              "parts a rigid wall without friction or rolling resistance (the grains slide "
              "and spin freely along it; its normal law is the part's grain-wall law, with "
              "wall_restitution); FEM nodes on the plane (within 1e-9 of the domain's extent) "
              "keep zero velocity normal to it. A face here is not also in a part's walls or "
              "absorbing_walls; SPH parts "
              "with wall_slip = \"no\" and walls cannot have them. Every output (masses, "
              "energies, forces, counts) is that of the modelled part of the domain."),
          "[]"),
  };
  return t;
}

TableSchema make_material() {
  TableSchema t{"materials",
                "Materials, referenced by name from parts. `model` selects the law and its "
                "keys.",
                {},
                "model",
                {}};
  t.keys = {
      required(text("name", "Name used by parts' `material`.")),
      required(choice("model", material_models(), material_model_doc())),
  };
  // Each law's keys are its entry's (material_laws.cpp).
  for (const MaterialLaw& law : material_laws())
    t.variants[law.model] = law.keys;
  return t;
}

TableSchema make_region() {
  TableSchema t{"parts.region", "The space a part fills. `type` selects the keys.", {}, "type", {}};
  t.keys = {required(choice("type", {"box", "layer", "disk", "sphere"},
                            "box (2D/3D), layer (a box across the whole domain, 2D/3D), disk "
                            "(2D only) or sphere (3D only)."))};
  t.variants["box"] = {required(vec("min_m", "m", "Lower corner.")),
                       required(vec("max_m", "m", "Upper corner."))};
  t.variants["layer"] = {
      required(real("bottom_m", "m",
                    "Height of the layer's bottom face along the vertical axis (y in 2D, z in "
                    "3D).")),
      required(positive(real("thickness_m", "m",
                             "The layer's thickness: its top face is at bottom_m + thickness_m. "
                             "Across, it spans the domain ([domain] min_m to max_m)."))),
  };
  t.variants["disk"] = {required(vec("center_m", "m", "Centre.")),
                        required(positive(real("radius_m", "m", "Radius.")))};
  t.variants["sphere"] = t.variants["disk"];
  return t;
}

TableSchema make_initial() {
  TableSchema t{"parts.initial", "Initial state of the part's material.", {}, {}, {}};
  t.keys = {
      positive(real("density_kg_m3", "kg/m^3", "Initial density. Unset: the material's rho0.")),
      at_least(real("pressure_pa", "Pa",
                    "Initial pressure (ideal gas: sets the internal energy). Unset: 0, or for "
                    "JWL the unreacted explosive."),
               0),
      vec("velocity_m_s", "m/s", "Initial velocity. Unset: at rest."),
  };
  return t;
}

TableSchema make_sph() {
  TableSchema t{"parts.sph", "SPH numerics of the part (paper section II-B).", {}, {}, {}};
  t.keys = {
      with_default(choice("kernel", {"wendland_c2", "cubic_spline"},
                          "Smoothing kernel (paper eq. 28: Wendland C2)."),
                   "\"wendland_c2\""),
      with_default(
          choice("density", {"continuity", "summation"},
                 "How the density is found. continuity: integrated from the continuity equation "
                 "(paper eq. 32), the paper's method; keeps the density of a free surface or a "
                 "charge's edge. summation: rho_i = sum_j m_j W(r_ij, h_i) over the particle "
                 "and its neighbours (mirror images and wall particles included) at each force "
                 "stage, with h_i = h_factor (m_i/rho_i)^(1/D) solved with it (Newton) when "
                 "variable_h is on, and the pressure terms in their grad-h form (Springel & "
                 "Hernquist 2002, Price 2012); follows the particles where a gas rarefies (the "
                 "Sedov blast's centre: docs/validation.md) but reads low where the particles "
                 "have no neighbours on one side (a free surface, a charge's edge). h is at "
                 "most 3 h_factor (m/rho0)^(1/D). docs/theory.md, section 2."),
          "\"continuity\""),
      with_default(at_most(at_least(real("h_factor", "1",
                                         "Smoothing length h = h_factor x "
                                         "spacing_m."),
                                    1.0),
                           3.0),
                   "1.3"),
      with_default(at_least(real("av_alpha", "1", "Monaghan artificial viscosity alpha."), 0),
                   "1.0"),
      with_default(at_least(real("av_beta", "1", "Monaghan artificial viscosity beta."), 0), "2.0"),
      with_default(at_most(positive(real("cfl", "1",
                                         "Courant number of the SPH stable step (signal "
                                         "speed).")),
                           1.0),
                   "0.3"),
      with_default(flag("variable_h",
                        "Smoothing length follows the density, h = h_0 (rho_0/rho)^(1/D) "
                        "(paper eq. 37, integrated)."),
                   "true"),
      with_default(at_most(at_least(real("xsph_epsilon", "1",
                                         "XSPH velocity smoothing epsilon (eq. 39); 0: off."),
                                    0),
                           1),
                   "0"),
      with_default(at_most(at_least(real("tensile_epsilon", "1",
                                         "Tensile-instability correction epsilon (eq. 38, "
                                         "Monaghan 2000); 0: off, 0.2 typical."),
                                    0),
                           1),
                   "0"),
      with_default(
          at_least(real("viscosity_pa_s", "Pa s",
                        "Dynamic viscosity of the laminar term (eq. 36); 0: inviscid. Adds the "
                        "viscous step limit 0.125 h^2 rho / mu."),
                   0),
          "0"),
      with_default(
          at_most(at_least(real("conductivity_alpha", "1",
                                "Artificial thermal conductivity alpha_u (Price 2008): heat flows "
                                "between neighbours at the signal speed sqrt(abs(p_i - p_j) / "
                                "rho_ij), which smooths the specific energy across a contact "
                                "discontinuity (the pressure blip of a shock tube) and vanishes "
                                "where the pressure is smooth. 0: off; 1: Price's value. Its "
                                "effect on crater's shock tube: docs/validation.md (Sod)."),
                           0),
                  1),
          "0"),
      with_default(choice_list("walls", {"left", "right", "bottom", "top", "back", "front"},
                               "Domain faces that are walls: left/right = x min/max, bottom/top = "
                               "y min/max, back/front = z min/max (3D). The fluid fills up to a "
                               "walled face. How the wall is held: see wall_slip."),
                   "[]"),
      with_default(
          at_most(
              at_least(whole("wall_layers",
                             "No-slip walls: least number of layers of dummy wall particles (at "
                             "spacing_m); more are laid when the kernel support of the largest "
                             "particle (2 h) needs them. Unused by free-slip walls."),
                       1),
              6),
          "3"),
      with_default(choice("wall_slip", {"free", "no"},
                          "free: each wall is a plane of symmetry, held by mirror images of the "
                          "particles near it (exact for a symmetry plane, e.g. half a charge). "
                          "no: no slip, held by fixed dummy particles (Adami et al. 2012)."),
                   "\"free\""),
  };
  return t;
}

TableSchema make_detonation() {
  TableSchema t{"parts.detonation",
                "Where an explosive part is lit (programmed burn: a particle lights at time_s + "
                "its distance to the initiator / D): a point, a plane (a plane-wave lens: one "
                "entry instead of a point per particle row) or a line (a detonating cord).",
                {},
                {},
                {}};
  t.keys = {
      with_default(choice("shape", {"point", "plane", "line"},
                          "point: at point_m; plane: the plane through point_m normal to "
                          "`normal`; line: the line through point_m along `direction` (in "
                          "2D a line and a plane are the same)."),
                   "\"point\""),
      required(vec("point_m", "m",
                   "The detonation point, or a point of the plane or line; inside the "
                   "domain.")),
      vec("normal", "1", "A plane's normal (any length but zero). Only with shape = plane."),
      vec("direction", "1", "A line's direction (any length but zero). Only with shape = line."),
      with_default(at_least(real("time_s", "s", "Time the initiator lights."), 0), "0")};
  return t;
}

TableSchema make_zone();

const TableSchema& region_schema() {
  static const TableSchema s = make_region();
  return s;
}
const TableSchema& initial_schema() {
  static const TableSchema s = make_initial();
  return s;
}
TableSchema make_bond() {
  TableSchema t{"parts.dem.bonds",
                "Parallel bonds (Potyondy & Cundall 2004; paper eqs. 17-24): cement between "
                "grains whose gap at t = 0 is at most gap_fraction x the smaller radius. A bond "
                "carries force and moment in parallel with the contact and breaks for good when "
                "its tensile or shear stress reaches the strength.",
                {},
                {},
                {}};
  t.keys = {
      with_default(flag("enabled", "Bond the grains at t = 0."), "false"),
      with_default(choice("radius_rule", {"min", "mean", "effective"},
                          "Bond radius R: min = multiplier x min(r1, r2) (Potyondy & Cundall); "
                          "mean = multiplier x (r1 + r2)/2, effective = multiplier x r1 r2 / "
                          "(r1 + r2) (the paper's two forms)."),
                   "\"min\""),
      with_default(positive(real("radius_multiplier", "1", "lambda of the bond radius.")), "1.0"),
      positive(real("normal_stiffness_pa_m", "Pa/m",
                    "Normal stiffness per unit area k_n of the cement. Required when enabled.")),
      positive(real("shear_stiffness_pa_m", "Pa/m",
                    "Shear stiffness per unit area k_s of the cement. Unset: the normal one.")),
      positive(real("tensile_strength_pa", "Pa",
                    "Tensile strength sigma_c: the bond breaks when F_n/A + abs(M_b) R / I "
                    "reaches it. Required when enabled.")),
      positive(
          real("shear_strength_pa", "Pa",
               "Shear strength tau_c: the bond breaks when abs(F_s)/A (+ abs(M_t) R / J in 3D) "
               "reaches it. Required when enabled.")),
      with_default(at_least(real("gap_fraction", "1",
                                 "Pairs whose surface gap at t = 0 is at most this x the "
                                 "smaller radius are bonded (overlapping pairs always)."),
                            0),
                   "0.01"),
  };
  return t;
}

const TableSchema& bond_schema() {
  static const TableSchema s = make_bond();
  return s;
}

TableSchema make_wall_motion() {
  TableSchema t{"parts.dem.wall_motion",
                "A rigid wall of the part (one of its walls) that moves along its axis: at a "
                "constant normal velocity, or servo-controlled to hold the mean normal stress it "
                "exerts on the grains (biaxial and triaxial tests; docs/theory.md, DEM, moving "
                "walls). Its position, velocity, force and stress are history.csv columns "
                "<part>_wall_<face>_position_m, _velocity_m_s, _force_n and _stress_pa (a wall "
                "with velocity_m_s = 0 reports the load on a fixed wall). It stands still "
                "outside its entries' windows, stops at the domain's face, and stands at "
                "position_m while the packing settles.",
                {},
                {},
                {}};
  t.keys = {
      required(choice("face", {"left", "right", "bottom", "top", "back", "front"},
                      "The wall that moves: one of the part's walls. A face may have several "
                      "entries whose windows [start_s, end_s) do not overlap (a servo, then a "
                      "constant speed).")),
      real("position_m", "m",
           "The wall's coordinate on its axis at t = 0 (and while the packing settles), inside "
           "the domain; in one entry of the face. Unset: the domain's face."),
      real("velocity_m_s", "m/s",
           "Constant normal velocity of the wall, along the face's outward normal: positive "
           "moves it away from the grains (the box grows), negative into them (compression). "
           "Give velocity_m_s or stress_pa."),
      with_default(at_least(real("ramp_s", "s",
                                 "velocity_m_s: the speed is reached linearly over this time "
                                 "after start_s, so that a fast wall does not strike the "
                                 "grains (a jump of v sends a stress wave of about rho c_p v). "
                                 "0: at once."),
                            0),
                   "0"),
      positive(real("stress_pa", "Pa",
                    "Servo target sigma*: the wall moves so that its normal force over its "
                    "current area (2D: per metre of depth, over its length; the length and the "
                    "area span the walls of the other axes where there are some, else the "
                    "domain) stays at sigma* (compression): its outward speed is servo_gain "
                    "(F_el - sigma* A) / (K dt), F_el and K the summed elastic normal force and "
                    "stiffness of its contacts (their dashpots left out), at most "
                    "max_speed_m_s; with no contact it moves in at max_speed_m_s.")),
      with_default(at_most(positive(real("servo_gain", "1",
                                         "stress_pa: the fraction alpha of the force error the "
                                         "wall closes in one step, assuming the grains stand "
                                         "still (PFC's servo with alpha = 0.5; YADE's "
                                         "TriaxialStressController closes 1 - wallDamping = "
                                         "0.75); below 1 for stability.")),
                           1),
                   "0.5"),
      with_default(positive(real("max_speed_m_s", "m/s",
                                 "stress_pa: the wall's largest speed, so that it approaches "
                                 "and follows the grains quasi-statically.")),
                   "0.1"),
      with_default(at_least(real("start_s", "s", "The wall moves from this time on."), 0), "0"),
      positive(real("end_s", "s", "The wall stops at this time. Unset: never.")),
  };
  return t;
}

const TableSchema& wall_motion_schema() {
  static const TableSchema s = make_wall_motion();
  return s;
}

TableSchema make_dem() {
  TableSchema t{"parts.dem", "DEM numerics of the part (paper section II-A).", {}, {}, {}};
  t.keys = {
      with_default(choice("contact", {"hertz_mindlin", "linear_spring"},
                          "Contact law. hertz_mindlin: Hertz normal, Mindlin no-slip tangential "
                          "with history, Coulomb limit, damping from the restitution (LIGGGHTS' "
                          "hertz); stiffness from the material. linear_spring: k_n, k_s springs "
                          "(paper eqs. 2-16) with dashpots from the restitution and the same "
                          "history and Coulomb limit; needs normal_stiffness_n_m."),
                   "\"hertz_mindlin\""),
      with_default(choice("hertz_2d", {"single_sphere", "row_of_spheres"},
                          "2D with hertz_mindlin: how a disk (mass per metre of depth) meets the "
                          "sphere law. single_sphere: the law as it is, on the disk's mass "
                          "(LAMMPS' and LIGGGHTS' 2D), a contact about 1/(2r) times too soft "
                          "for grains per metre of depth. row_of_spheres: the disk is a row of "
                          "spheres along the depth, pitch p = r1 + r2 (2r at a wall): force per "
                          "metre = one sphere contact's / p, with mass m* p; use it when the "
                          "grains meet SPH or FE parts (docs/theory.md, DEM)."),
                   "\"single_sphere\""),
      positive(real("normal_stiffness_n_m", "N/m",
                    "linear_spring: normal stiffness k_n of grain-grain and grain-wall "
                    "contacts (2D: per metre of depth). Required with linear_spring.")),
      positive(real("shear_stiffness_n_m", "N/m",
                    "linear_spring: shear stiffness k_s. Unset: Mindlin's ratio for equal "
                    "grains, k_s = k_n 2(1 - nu)/(2 - nu) (nu of the material).")),
      with_default(at_most(positive(real("stiffness_step_fraction", "1",
                                         "Stable step = this x sqrt(m_min / k_max) for "
                                         "linear springs and bonds (m_min: the smallest "
                                         "grain; k_max: the largest spring, contact plus "
                                         "bond); 0.17 after O'Sullivan & Bray 2004.")),
                           1),
                   "0.17"),
      positive(real("radius_min_m", "m",
                    "Smallest grain radius; radii are uniform in [radius_min_m, radius_max_m]. "
                    "Unset: spacing_m / 2.")),
      positive(real("radius_max_m", "m",
                    "Largest grain radius, at most spacing_m / 2. Unset: "
                    "spacing_m / 2.")),
      with_default(at_least(whole("seed", "Seed of the radius draw."), 0), "1"),
      with_default(at_most(at_least(real("local_damping", "1",
                                         "Cundall local damping alpha (eq. 25): 0.157 dynamic, "
                                         "0.7 quasi-static, 0 off."),
                                    0),
                           1),
                   "0"),
      with_default(at_most(positive(real("rayleigh_fraction", "1",
                                         "Stable step = this x the Rayleigh step of the "
                                         "smallest grain.")),
                           1),
                   "0.25"),
      with_default(at_least(real("rolling_friction", "1",
                                 "Rolling friction coefficient mu_r of the elastic-plastic "
                                 "rolling spring (Ai et al. 2011, model C): limit torque "
                                 "mu_r R* abs(F_n); grain-grain and grain-wall. 0: off."),
                            0),
                   "0"),
      with_default(at_least(real("rolling_damping", "1",
                                 "Rolling damping ratio eta_r of the rolling spring (Ai et al. "
                                 "use 0.3); acts while the rolling spring is below its limit."),
                            0),
                   "0"),
      with_default(flag("rate_dependent_friction",
                        "Friction angle rises with the contact strain rate: phi_dyn = "
                        "phi_s (1 + beta log10(rate / rate_0)) above rate_0, rate = "
                        "abs(v_n) / (r_1 + r_2) (paper section III-C)."),
                   "false"),
      with_default(
          at_least(
              real("friction_rate_beta", "1", "beta of rate_dependent_friction (paper: 0.05)."), 0),
          "0.05"),
      with_default(positive(real("friction_reference_strain_rate", "1/s",
                                 "Reference strain rate rate_0 of rate_dependent_friction.")),
                   "1.0"),
      with_default(choice_list("walls", {"left", "right", "bottom", "top", "back", "front"},
                               "Domain faces that are rigid walls for the grains."),
                   "[]"),
      with_default(at_least(real("wall_friction", "1", "Grain-wall friction coefficient."), 0),
                   "0.5"),
      with_default(
          at_most(positive(real("wall_restitution", "1", "Grain-wall coefficient of restitution.")),
                  1),
          "0.5"),
      with_default(
          choice_list(
              "absorbing_walls", {"left", "right", "bottom", "top", "back", "front"},
              "Domain faces that are absorbing (viscous, Lysmer-Kuhlemeyer) walls, for the "
              "non-reflecting boundaries of a bed: a grain touching one gets its static reaction "
              "of t = 0 (the wall's elastic normal force at its initial overlap, so a bed settled "
              "on it keeps resting on it) plus dashpots rho c_p A on its normal and rho c_s A on "
              "its tangential velocity, A = 2r (2D, per metre of depth) or (2r)^2 (3D), the "
              "tangential one on grains of the bed (another grain pushes on them: a loose "
              "grain at rest on the face is not held up); the wall pushes, never pulls. A face "
              "reaches up to the highest grain centre that touched it at t = 0 (the ground "
              "beyond the model): above, it is open and applies nothing. The faces transmit: a "
              "grain whose centre crosses one leaves "
              "the model, its energy booked as outflow (left_domain_* in summary.json). While "
              "the packing settles they are rigid walls. A face is in walls or here, not both."),
          "[]"),
      positive(real("absorbing_wall_density_kg_m3", "kg/m^3",
                    "Bulk density rho of the bed behind the absorbing walls. Unset: the part's "
                    "grain mass over its region's volume less what the parts it is carved around "
                    "take (the bed's bulk density, as bulk_density_kg_m3 of summary.json).")),
      positive(real("absorbing_wall_p_wave_speed_m_s", "m/s",
                    "P-wave speed c_p of the bed behind the absorbing walls. Unset: with "
                    "linear_spring, the lattice estimate 2r sqrt(k_n/m) of the mean grain (exact "
                    "for a chain or a square/cubic lattice); with hertz_mindlin it is required "
                    "(dry sand near the surface: about 100-300 m/s).")),
      positive(real("absorbing_wall_s_wave_speed_m_s", "m/s",
                    "S-wave speed c_s of the bed behind the absorbing walls. Unset: c_p "
                    "sqrt((1 - 2 nu)/(2 - 2 nu)), nu the material's Poisson ratio.")),
      sub("bonds", KeyType::Table, bond_schema(),
          "Parallel bonds between the grains touching at t = 0."),
      sub("wall_motion", KeyType::TableArray, wall_motion_schema(),
          "Rigid walls that move (constant velocity or servo-controlled stress)."),
  };
  return t;
}

TableSchema make_packing() {
  TableSchema t{"parts.packing",
                "How the grains of a DEM part are laid: on the lattice (default), at random to "
                "a porosity, or densely from the floor up, then optionally settled under "
                "gravity. A settled packing is saved in cache_dir and reused by any later run "
                "with the same inputs.",
                {},
                {},
                {}};
  t.keys = {
      with_default(choice("method", {"lattice", "random", "dense"},
                          "lattice: one grain per lattice site (spacing_m) with radii drawn "
                          "from [radius_min_m, radius_max_m]. random: grains placed at random, "
                          "without overlap, until their volume is (1 - porosity) x the region's "
                          "(the column is extended against gravity when they do not fit). "
                          "dense: the box region filled from the floor up, each grain (radii "
                          "uniform in [radius_min_m, radius_max_m]) at the lowest place where "
                          "it rests on two (3D: three) supports: grains, walls, the bodies it is "
                          "carved around (solid fraction about 0.82 for disks of a 2.5:1 "
                          "range, 0.64 for spheres away from the walls); settle = true then "
                          "loads its contacts under gravity."),
                   "\"lattice\""),
      at_most(at_least(real("porosity", "1",
                            "random: target porosity of the region (void volume / region "
                            "volume). Sand 0.35-0.45."),
                       0.2),
              0.95),
      of_type(real("sieve_diameter_m", "m",
                   "random: sieve sizes of a grading curve, ascending (grain diameters). "
                   "Unset: radii uniform in [radius_min_m, radius_max_m] of [parts.dem]."),
              KeyType::RealArray),
      of_type(real("sieve_passing", "1",
                   "random: mass fraction passing each sieve of sieve_diameter_m, ascending "
                   "from 0 to 1 (grains are uniform in diameter within each class)."),
              KeyType::RealArray),
      with_default(flag("settle",
                        "Settle the grains under gravity before the run (on several MPI ranks: "
                        "the bed spread over them, with one rank's bits; rank 0 writes the "
                        "cache and sends the packing to the others)."),
                   "false"),
      with_default(positive(real("settle_kinetic_ratio", "1",
                                 "Settled when the grains' mean kinetic energy is below this x "
                                 "m g r of the mean grain.")),
                   "1e-4"),
      with_default(positive(real("settle_max_time_s", "s",
                                 "Settling gives up (input error, exit 2) after this much "
                                 "simulated time.")),
                   "2.0"),
      with_default(
          positive(real("settle_unbalanced_ratio", "1",
                        "dense: settled once also the grains' unbalanced force (the sum of "
                        "their net force magnitudes over their weight) is below this "
                        "(static equilibrium under gravity).")),
          "1e-3"),
      with_default(at_most(at_least(real("settle_damping", "1",
                                         "Cundall local damping during settling (0.7: "
                                         "quasi-static)."),
                                    0),
                           1),
                   "0.7"),
      at_most(positive(real("settle_safety_factor", "1",
                            "Fraction of the grains' stable step used while settling. Unset: "
                            "[time] safety_factor (which the coupled run may need small for "
                            "its own reasons; a DEM bed settles stably at 0.8).")),
              1),
      with_default(at_least(real("agitation_m_s", "m/s",
                                 "Random initial velocity of the grains (after settling), "
                                 "uniform in +-this per component, seeded by [parts.dem] seed; "
                                 "added to [parts.initial] velocity_m_s."),
                            0),
                   "0"),
      with_default(text("cache_dir",
                        "Directory for settled packings, relative to the scenario file. A file "
                        "is keyed by a hash of every input that shapes the packing."),
                   "\".crater-cache\""),
  };
  return t;
}

const TableSchema& packing_schema() {
  static const TableSchema s = make_packing();
  return s;
}

TableSchema make_dem_particle() {
  TableSchema t{"parts.particles", "One grain placed by hand.", {}, {}, {}};
  t.keys = {
      required(vec("center_m", "m", "Centre.")),
      required(positive(real("radius_m", "m", "Radius."))),
      vec("velocity_m_s", "m/s", "Initial velocity. Unset: at rest."),
  };
  return t;
}

const TableSchema& dem_schema() {
  static const TableSchema s = make_dem();
  return s;
}
const TableSchema& dem_particle_schema() {
  static const TableSchema s = make_dem_particle();
  return s;
}

const TableSchema& sph_schema() {
  static const TableSchema s = make_sph();
  return s;
}
const TableSchema& zone_schema() {
  static const TableSchema s = make_zone();
  return s;
}
const TableSchema& detonation_schema() {
  static const TableSchema s = make_detonation();
  return s;
}

TableSchema make_zone() {
  TableSchema t{"parts.zones",
                "Sub-regions of a part with their own initial state; later zones win. FEM nodes "
                "and DEM grains (by centre, after settling) take only velocity_m_s.",
                {},
                {},
                {}};
  t.keys = {
      required(sub("region", KeyType::Table, region_schema(), "Where the zone is.")),
      positive(real("spacing_m", "m",
                    "The zone's own particle spacing: its particles are laid on their own "
                    "lattice (e.g. equal particle masses across a density jump: spacing ratio "
                    "= (density ratio)^(1/D)). Unset: the part's lattice.")),
      positive(real("density_kg_m3", "kg/m^3", "Density in the zone. Unset: the part's.")),
      at_least(real("pressure_pa", "Pa",
                    "Pressure in the zone (ideal gas: sets the internal energy). Unset: the "
                    "part's."),
               0),
      vec("velocity_m_s", "m/s", "Velocity in the zone. Unset: the part's."),
  };
  return t;
}

TableSchema make_fem_boundary() {
  TableSchema t{"parts.fem.boundary",
                "A boundary condition on the nodes of one face of the part (or of a mesh "
                "group). Later entries win where they share nodes.",
                {},
                {},
                {}};
  t.keys = {
      required(choice("type", {"fixed", "symmetry", "velocity", "non_reflecting"},
                      "fixed: all velocity components zero. symmetry: the velocity normal to the "
                      "face zero (also a frictionless rigid wall). velocity: the given "
                      "components of velocity_m_s imposed. non_reflecting: viscous dashpots "
                      "rho c_p on the normal and rho c_s on the tangential velocity "
                      "(Lysmer-Kuhlemeyer), absorbing waves that reach the face.")),
      choice("face", {"left", "right", "bottom", "top", "back", "front"},
             "A face of the part's bounding box: left/right = x min/max, bottom/top = y min/max, "
             "back/front = z min/max. Give face or group."),
      text("group", "A physical group of the mesh file (lines in 2D, surfaces in 3D)."),
      vec("velocity_m_s", "m/s", "velocity: the imposed velocity. Unset: at rest."),
      choice_list("components", {"x", "y", "z"},
                  "velocity: the components imposed; the others stay free. Unset: all."),
  };
  return t;
}
const TableSchema& fem_boundary_schema() {
  static const TableSchema s = make_fem_boundary();
  return s;
}

TableSchema make_rigid_wall() {
  TableSchema t{"parts.fem.rigid_walls",
                "Fixed planes the part's nodes cannot cross (LS-DYNA's *RIGIDWALL_PLANAR): a "
                "node that would cross one has the inward part of its normal velocity removed "
                "and lands on it, with Coulomb friction on its tangential velocity; a node pulled "
                "away leaves it, so a body can rebound (unlike a symmetry boundary). The "
                "kinetic energy a wall removes is booked as its work (external_work_j).",
                {},
                {},
                {}};
  t.keys = {
      required(vec("point_m", "m", "A point of the plane.")),
      required(vec("normal", "1",
                   "The plane's normal, pointing to the side the part is on (any length but "
                   "zero). A node that starts behind the wall is refused.")),
      with_default(at_least(real("friction", "1", "Coulomb friction coefficient."), 0), "0"),
  };
  return t;
}
const TableSchema& fem_rigid_wall_schema() {
  static const TableSchema s = make_rigid_wall();
  return s;
}

TableSchema make_fem_load() {
  TableSchema t{"parts.fem.loads",
                "A load on the boundary faces of one face of the part's bounding box (or of a "
                "mesh group), applied as nodal forces on the current (deformed) faces every "
                "step; its work is the part's external work. Faces of eroded elements are no "
                "longer loaded.",
                {},
                {},
                {}};
  t.keys = {
      required(choice("type", {"pressure"},
                      "pressure: a pressure history p(t), positive pushing into the body, on "
                      "each loaded face: f = -p A n (A the face's current area, 2D: length x "
                      "1 m; n its outward normal), shared equally by the face's nodes.")),
      choice("face", {"left", "right", "bottom", "top", "back", "front"},
             "The face of the part's bounding box whose boundary faces are loaded: "
             "left/right = x min/max, bottom/top = y min/max, back/front = z min/max. Give "
             "face or group."),
      text("group",
           "A physical group of the mesh file (lines in 2D, surfaces in 3D): its boundary "
           "faces are loaded, curved or not (a tunnel's wall). Not with region."),
      absent_means_unset(sub("region", KeyType::Table, region_schema(),
                             "Only the faces whose centre (at t = 0) lies in this box are "
                             "loaded; the box's extent along the face normal is not used. "
                             "Unset: the whole face.")),
      required(of_type(
          real("time_s", "s", "Times of the pressure table, strictly increasing (at least 2)."),
          KeyType::RealArray)),
      required(of_type(real("pressure_pa", "Pa",
                            "Pressure at each time of time_s; linear in between, zero before the "
                            "first and after the last time."),
                       KeyType::RealArray)),
  };
  return t;
}
const TableSchema& fem_load_schema() {
  static const TableSchema s = make_fem_load();
  return s;
}

TableSchema make_fem_geostatic() {
  TableSchema t{"parts.fem.geostatic",
                "An initial geostatic stress (docs/theory.md, section 4): at t = 0 each "
                "element's stress at its centre, at depth d below the surface, is sigma_v = "
                "-rho0 g d on gravity's axis and sigma_h = k0 sigma_v on the other axes (2D: "
                "also the plane-strain z), no shear, tension positive; zero above the surface. "
                "Needs [domain] gravity_m_s2 along one axis; not for holmquist_johnson_cook "
                "materials. In equilibrium with the weight when the base is supported and the "
                "sides are held normal to themselves (symmetry); a state outside the material's "
                "yield surface is returned onto it in the first step (with a warning).",
                {},
                {},
                {}};
  t.keys = {
      required(real("surface_m", "m",
                    "The free ground surface: its coordinate on the axis gravity acts along "
                    "(e.g. y = 0 for gravity (0, -9.81)); depth is measured from it in the "
                    "direction of gravity.")),
      positive(real("k0", "1",
                    "Coefficient of lateral earth pressure at rest K_0 = sigma_h / sigma_v (e.g. "
                    "Jaky's 1 - sin(phi) for a normally consolidated sand). Unset: nu / (1 - nu) "
                    "of the material's Poisson's ratio (an elastic layer in uniaxial strain).")),
  };
  return t;
}
const TableSchema& fem_geostatic_schema() {
  static const TableSchema s = make_fem_geostatic();
  return s;
}

TableSchema make_fem() {
  TableSchema t{"parts.fem",
                "Explicit finite-element numerics of the part (paper section III-B): one-point "
                "Q4 (2D plane strain) or Hex8 (3D) elements, lumped mass, central difference.",
                {},
                {},
                {}};
  t.keys = {
      with_default(choice("hourglass", {"viscous", "stiffness"},
                          "Flanagan-Belytschko hourglass control form (LS-DYNA types 3 and 5)."),
                   "\"viscous\""),
      at_most(at_least(real("hourglass_coefficient", "1",
                            fmt::format("Hourglass coefficient kappa (LS-DYNA QM). Unset: {} with "
                                        "hourglass = \"viscous\" (LS-DYNA's default), {} with "
                                        "\"stiffness\", which stiffens large plastic flow at 0.1 "
                                        "(0.03-0.05 is the range usually advised for LS-DYNA's "
                                        "stiffness forms; docs/theory.md).",
                                        kHourglassViscousDefault, kHourglassStiffnessDefault)),
                       0),
              0.5),
      with_default(at_least(real("bulk_viscosity_quadratic", "1",
                                 "Quadratic bulk viscosity coefficient C_0 (LS-DYNA Q1)."),
                            0),
                   "1.5"),
      with_default(at_least(real("bulk_viscosity_linear", "1",
                                 "Linear bulk viscosity coefficient C_1 (LS-DYNA Q2)."),
                            0),
                   "0.06"),
      positive(real("initial_temperature_k", "K",
                    "Initial temperature of a Johnson-Cook part (a warning when it is not the "
                    "material's room_temperature_k). Unset: the material's room_temperature_k. "
                    "Other materials have no temperature (an error if set).")),
      positive(real("erosion_plastic_strain", "1",
                    "Elements erode when their effective plastic strain reaches this (as "
                    "LS-DYNA's *MAT_ADD_EROSION). Unset: only Johnson-Cook damage erodes.")),
      with_default(flag("erode_inverted",
                        "An element turned inside out (volume <= 0) erodes, and the run "
                        "goes on; false: the run stops (exit 3) naming it."),
                   "false"),
      with_default(
          at_most(at_least(real("erosion_step_ratio", "1",
                                "Elements whose stable step falls below this fraction of the "
                                "part's initial stable step erode (as LS-DYNA's ERODE = 1 with "
                                "DTMIN): a crushed element no longer holds the whole model's "
                                "step down. 0: off."),
                           0),
                  1),
          "0"),
      with_default(
          at_most(at_least(real("mass_scaling_step_ratio", "1",
                                "Selective mass scaling (as LS-DYNA's DT2MS < 0): an element "
                                "whose stable step falls below this fraction of the part's "
                                "initial stable step gains the mass that keeps its step there, "
                                "shared by its nodes; their momentum is kept. An alternative to "
                                "erosion_step_ratio. 0: off."),
                           0),
                  1),
          "0"),
      with_default(at_most(positive(real("mass_scaling_limit", "1",
                                         "The most mass that mass scaling may add, as a "
                                         "fraction of the part's initial mass; past it the run "
                                         "stops (exit 3) naming the element.")),
                           1),
                   "0.01"),
      text("mesh_file",
           "A Gmsh mesh (.msh format 4.1, ASCII), relative to the scenario file: 4-node "
           "quadrangles (2D) or 8-node hexahedra (3D). Unset: a structured mesh of the part's "
           "box region with elements of size spacing_m."),
      text("mesh_group",
           "The physical group of mesh_file holding the part's elements. Unset: every "
           "element of the scenario's dimension."),
      sub("boundary", KeyType::TableArray, fem_boundary_schema(),
          "Boundary conditions. Faces without one are free (traction-free)."),
      sub("rigid_walls", KeyType::TableArray, fem_rigid_wall_schema(),
          "Planar rigid walls the nodes rebound from."),
      sub("loads", KeyType::TableArray, fem_load_schema(),
          "Loads on boundary faces (an equivalent blast pressure, a surcharge)."),
      absent_means_unset(sub("geostatic", KeyType::Table, fem_geostatic_schema(),
                             "Start from the geostatic stress of a ground at rest, e.g. "
                             "geostatic = { surface_m = 0.0, k0 = 0.5 }. Unset: the part "
                             "starts unstressed.")),
  };
  return t;
}
const TableSchema& fem_schema() {
  static const TableSchema s = make_fem();
  return s;
}

TableSchema make_part() {
  TableSchema t{"parts",
                "Bodies of the model, one method each. `method` selects the keys.",
                {},
                "method",
                {}};
  t.keys = {
      required(text("name", "Unique part name; names output files.")),
      required(choice("method", {"sph", "dem", "fem"},
                      "Discretisation: sph (fluids, explosives), dem (grains) or fem (solids).")),
      required(text("material", "Name of an entry of [[materials]].")),
      positive(real("spacing_m", "m",
                    "Particle spacing (lattice pitch); for fem the element size of the "
                    "structured mesh. Required unless fem.mesh_file is given or the "
                    "part's DEM grains are placed by hand ([[parts.particles]]).")),
      absent_means_unset(sub("region", KeyType::Table, region_schema(),
                             "Where the part is (fem: a box). Required unless fem.mesh_file is "
                             "given or the grains are placed by hand ([[parts.particles]]).")),
      sub("initial", KeyType::Table, initial_schema(), "Initial state."),
      sub("zones", KeyType::TableArray, zone_schema(),
          "Zones with their own initial state, inside the part's region."),
      of_type(text("carve",
                   "Parts whose regions this part's particles leave empty (sph and dem parts): a "
                   "particle is not laid where its disk or sphere would reach into them. Lets "
                   "a soil box hold a charge and a plate. Those parts may overlap this one."),
              KeyType::StringArray),
  };
  t.variants["dem"] = {
      sub("dem", KeyType::Table, dem_schema(), "DEM numerics."),
      sub("particles", KeyType::TableArray, dem_particle_schema(),
          "Grains placed one by one (tests, small setups) instead of the region's lattice."),
      sub("packing", KeyType::Table, packing_schema(),
          "How the grains are laid and settled. Unset: on the lattice, not settled."),
  };
  t.variants["fem"] = {
      sub("fem", KeyType::Table, fem_schema(), "FEM numerics and boundary conditions."),
  };
  t.variants["sph"] = {
      sub("sph", KeyType::Table, sph_schema(), "SPH numerics."),
      sub("detonation", KeyType::TableArray, detonation_schema(),
          "Detonation points (JWL materials only). None: the part starts as detonation "
          "products at the CJ energy (constant-volume burn)."),
  };
  return t;
}

TableSchema make_gauge() {
  TableSchema t{"gauges",
                "History output at chosen entities, as LS-DYNA's *DATABASE_HISTORY_NODE and "
                "_SOLID: fields of one part at a point or at entity ids, written to gauges.csv "
                "every output.gauges_every_steps steps, at every frame and at the end, one column "
                "per gauge, entity, field and component (`<gauge>.<node|particle|element><id>."
                "<field>[_x|_y|_z|_xx|...]`), or one per gauge, field and component for a sum "
                "(`sum`, `face`: `<gauge>.sum.<field>...`). Values are those a VTU frame of the "
                "same step holds; NaN for a particle that has left the domain.",
                {},
                {},
                {}};
  t.keys = {
      required(
          text("name", "The gauge's name (1-64 of A-Z a-z 0-9 _ - .), the start of its columns.")),
      required(text("part", "The part it reads, by name.")),
      required(of_type(text("fields",
                            "Output fields of the part, by their names in its VTU files, e.g. "
                            "[\"velocity\", \"von_mises\"]. A name the part does not write is "
                            "refused before the run, with the part's fields listed."),
                       KeyType::StringArray)),
      vec("point_m", "m",
          "Where: the node or particle nearest this point at t = 0 (for point fields) and the "
          "element whose centre is nearest (cell fields). Not with ids or element_ids."),
      of_type(real("ids", "1",
                   "Node ids (FEM, the VTU point order) or particle ids (SPH, DEM: the `id` "
                   "field, which stays with a particle) for the point fields."),
              KeyType::RealArray),
      of_type(real("element_ids", "1", "FEM element ids (the VTU cell order) for cell fields."),
              KeyType::RealArray),
      choice("face", {"left", "right", "bottom", "top", "back", "front"},
             "FEM: the nodes on this face of the part's bounding box at t = 0 (left/right = x "
             "min/max, bottom/top = y, back/front = z), summed: the resultant on the face, as "
             "LS-DYNA's *DATABASE_NODAL_FORCE_GROUP, of point fields such as reaction_force "
             "(the supports' force, e.g. on a held face), internal_force (the elements' force "
             "on the nodes) or contact_force. Columns `<gauge>.sum.<field>_x`. Not with point_m, "
             "ids or element_ids."),
      with_default(flag("sum",
                        "With ids or element_ids: write the sum over those entities of each "
                        "field (columns `<gauge>.sum.<field>...`) instead of one column per "
                        "entity; in entity order, so the same on any thread count. A face always "
                        "sums."),
                   "false"),
  };
  return t;
}

TableSchema make_contact() {
  TableSchema t{"contacts",
                "Contacts between parts (paper section III-D): penalty forces, equal and "
                "opposite, between the particles of one part and the surface of an FEM part "
                "(sph-fem, dem-fem), between the particles of an SPH and a DEM part, or "
                "between the surfaces of two FEM parts (fem-fem: nodes of each against the "
                "faces of the other).",
                {},
                {},
                {}};
  t.keys = {
      required(of_type(text("parts", "The two parts, by name, e.g. [\"charge\", \"plate\"]."),
                       KeyType::StringArray)),
      repeats_allowed(of_type(
          text("surface_groups",
               "Per part, in the order of parts: a physical group of the fem part's mesh file "
               "(surfaces in 3D, lines in 2D) the contact is restricted to: the faces of the "
               "part's surface whose nodes are all in the group, and their nodes (a tunnel's "
               "lining against the soil by [\"lining_outer\", \"soil_inner\"], not by the "
               "lining's inner wall or the soil's far faces). \"\": the part's whole surface, "
               "and for a particle part. Faces that erosion exposes count when their nodes are "
               "in the group: a contact that must follow erosion through a wall keeps the whole "
               "surface. Unset: the whole surfaces."),
          KeyType::StringArray)),
      with_default(positive(real("penalty_scale", "1",
                                 "Scale s of the penalty stiffness: particle-surface k = s K A^2 / "
                                 "V of the face's element (K its bulk modulus, A the face area, V "
                                 "its volume; LS-DYNA's segment stiffness), fem-fem the "
                                 "smaller of that of the face and of the node's own stiffest "
                                 "face, particle-particle "
                                 "k = s E r (3D) or s E (2D) with the grain's Young's modulus. "
                                 "The paper uses 0.1 for sph-fem, 1 for dem-fem.")),
                   "1.0"),
      with_default(at_least(real("friction", "1",
                                 "Coulomb friction coefficient at the contact (the paper's "
                                 "soil-steel 0.4)."),
                            0),
                   "0"),
      with_default(at_most(at_least(real("damping_ratio", "1",
                                         "Viscous damping of the normal penalty force as a "
                                         "fraction of critical."),
                                    0),
                           1),
                   "0.1"),
  };
  return t;
}

TableSchema make_probes() {
  TableSchema t{"probes",
                "The paper's measurements (docs/theory.md, \"Probes\"): summary.json `metrics`, "
                "surface_profile.csv and the plate's peak stress in history.csv.",
                {},
                {},
                {}};
  t.keys = {
      text("plate",
           "The fem part measured as the plate: plate_peak_von_mises_pa (at stress_time_s), "
           "plate_peak_von_mises_max_pa, plate_eroded_elements, plate_perforated, "
           "plate_perforated_area_m2, and the history.csv column plate_max_von_mises_pa."),
      text("soil",
           "The dem part whose surface (with the plate's) is the ground: surface_profile.csv, "
           "surface_settlement_max_m, surface_settlement_max_x_m (3D: _r_m), crater_depth_m, "
           "crater_radius_m, crater_radius_lower_bound (1: the crater reaches the domain's side, "
           "its radius is a lower bound), delamination_gap_max_m."),
      with_default(at_least(real("stress_time_s", "s",
                                 "Time of plate_peak_von_mises_pa (the paper's figures: 0.6 ms)."),
                            0),
                   "6.0e-4"),
      positive(
          real("surface_bin_m", "m",
               "Width of the columns (and height of the cells) in which the ground surface "
               "is found. Unset: 8 x the soil's largest grain radius (cells of some 15 grains).")),
      of_type(real("axis_m", "m",
                   "3D only: [x, y], the horizontal position of the crater's axis, about which "
                   "surface_profile.csv is averaged in rings and crater_radius_m is measured. "
                   "Unset: the first detonation point of the first sph part that has one, else "
                   "the full model's horizontal centre (on the domain's symmetry planes: the "
                   "corner of a quarter model)."),
              KeyType::RealArray),
      text("lining",
           "The fem part measured as a tunnel's lining (src/solver/lining_probe.hpp): history.csv "
           "columns lining_crown_radial_m, lining_springline_radial_m, lining_invert_radial_m "
           "(the inner wall's displacement away from the axis, at the nodes nearest the cross-"
           "section through lining_axis_point_m: the highest, the one furthest across, the "
           "lowest); summary.json lining_crown_displacement_max_m (the largest outward radial "
           "displacement of the crown over the steps) and _min_m (the largest inward), the same "
           "for springline and invert, lining_damage_max, lining_damaged_volume_m3 (elements "
           "with damage >= 0.5 or eroded, volume at t = 0, the full model's: x 2 per plane of "
           "symmetry), lining_eroded_elements."),
      text("lining_soil",
           "With lining: the fem part around it, measured along the crown line (the vertical "
           "through the crown gauge's node, upwards, at t = 0) at the nodes it has on that line "
           "(within 1e-3 of the lining's inner radius; the run stops with exit 2 if there are "
           "none): crown_line.csv (per node, from the lining up: height, depth below the "
           "highest, the largest and smallest upward displacement over the steps, the last); "
           "history.csv columns soil_crown_line_interface_up_m and soil_crown_line_surface_up_m "
           "(the lowest and highest of those nodes); summary.json "
           "soil_crown_line_interface_displacement_max_m / _min_m and the same for surface."),
      of_type(real("lining_axis_point_m", "m",
                   "A point on the tunnel's axis, where the gauges' cross-section is (e.g. the "
                   "charge's centre). Required with lining."),
              KeyType::RealArray),
      of_type(real("lining_axis_direction", "1",
                   "3D: the direction of the tunnel's axis, horizontal ([x, y, 0]). Unset: "
                   "[0, 1, 0], along y. In 2D the axis is perpendicular to the plane."),
              KeyType::RealArray),
  };
  return t;
}

}  // namespace

const TableSchema& scenario_schema() {
  static const TableSchema scenario = make_scenario();
  static const TableSchema time = make_time();
  static const TableSchema output = make_output();
  static const TableSchema domain = make_domain();
  static const TableSchema material = make_material();
  static const TableSchema part = make_part();
  static const TableSchema contact = make_contact();
  static const TableSchema probes = make_probes();
  static const TableSchema gauge = make_gauge();
  static const TableSchema root = [] {
    TableSchema r{"", "A crater scenario file (TOML, SI units).", {}, {}, {}};
    r.keys = {
        required(sub("scenario", KeyType::Table, scenario, scenario.doc)),
        sub("time", KeyType::Table, time, time.doc),
        sub("output", KeyType::Table, output, output.doc),
        sub("domain", KeyType::Table, domain, domain.doc),
        required(sub("materials", KeyType::TableArray, material, material.doc)),
        required(sub("parts", KeyType::TableArray, part, part.doc)),
        sub("contacts", KeyType::TableArray, contact, contact.doc),
        sub("probes", KeyType::Table, probes, probes.doc),
        sub("gauges", KeyType::TableArray, gauge, gauge.doc),
    };
    return r;
  }();
  return root;
}

namespace {

std::string type_doc(const KeySchema& k) {
  if (k.type != KeyType::Choice && k.type != KeyType::ChoiceList) return words_of(k.type).doc;
  std::string s = k.type == KeyType::ChoiceList ? "array of " : "";
  for (std::size_t i = 0; i < k.choices.size(); ++i)
    s += (i ? " \\| " : "") + ("`\"" + k.choices[i] + "\"`");
  return s;
}

std::string range_doc(const KeySchema& k) {
  std::string s;
  if (k.min) s += fmt::format("{} {}", k.min_exclusive ? ">" : "≥", *k.min);
  if (k.max) s += fmt::format("{}≤ {}", s.empty() ? "" : ", ", *k.max);
  return s;
}

void key_rows(std::string& md, const std::vector<KeySchema>& keys) {
  md += "| key | type | unit | default | range | meaning |\n";
  md += "| --- | --- | --- | --- | --- | --- |\n";
  for (const auto& k : keys) {
    const std::string def =
        k.required ? "**required**" : (k.default_toml ? "`" + *k.default_toml + "`" : "unset");
    md += fmt::format("| `{}` | {} | {} | {} | {} | {} |\n", k.name, type_doc(k),
                      k.unit.empty() ? "" : k.unit, def, range_doc(k), k.doc);
  }
  md += "\n";
}

void table_section(std::string& md, const TableSchema& t, bool array,
                   std::vector<const TableSchema*>& done) {
  // A table used in several places (a region) is documented once.
  if (std::find(done.begin(), done.end(), &t) != done.end()) return;
  done.push_back(&t);
  const std::string header = array ? "[[" + t.name + "]]" : "[" + t.name + "]";
  md += fmt::format("## `{}`\n\n{}\n\n", header, t.doc);
  key_rows(md, t.keys);
  for (const auto& [name, keys] : t.variants) {
    md += fmt::format("### `{}` = `\"{}\"`\n\n", t.discriminator, name);
    key_rows(md, keys);
  }
  auto recurse = [&](const std::vector<KeySchema>& keys) {
    for (const auto& k : keys)
      if (k.sub) table_section(md, *k.sub, k.type == KeyType::TableArray, done);
  };
  recurse(t.keys);
  for (const auto& [name, keys] : t.variants)
    recurse(keys);
}

// Plain text for a terminal: no Markdown marks, the meaning wrapped under each key.
std::string plain(std::string s) {
  std::string out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '`') continue;
    if (s[i] == '\\' && i + 1 < s.size() && s[i + 1] == '|') continue;
    out += s[i];
  }
  return out;
}

void wrapped(std::string& out, const std::string& text, std::string_view indent) {
  constexpr std::size_t kWidth = 96;
  std::string line;
  std::size_t from = 0;
  while (from < text.size()) {
    std::size_t to = text.find(' ', from);
    if (to == std::string::npos) to = text.size();
    const std::string word = text.substr(from, to - from);
    from = to + 1;
    if (word.empty()) continue;
    if (!line.empty() && indent.size() + line.size() + 1 + word.size() > kWidth) {
      out += std::string(indent) + line + "\n";
      line.clear();
    }
    line += (line.empty() ? "" : " ") + word;
  }
  if (!line.empty()) out += std::string(indent) + line + "\n";
}

void key_text(std::string& out, const std::vector<KeySchema>& keys) {
  for (const auto& k : keys) {
    std::string head = fmt::format("  {:<26} {}", k.name, plain(type_doc(k)));
    if (!k.unit.empty() && k.unit != "1") head += " [" + k.unit + "]";
    head += k.required ? ", required"
                       : (k.default_toml ? ", default " + *k.default_toml : ", unset by default");
    if (const std::string r = range_doc(k); !r.empty()) head += ", " + r;
    out += head + "\n";
    wrapped(out, plain(k.doc), "      ");
  }
  out += "\n";
}

void table_text(std::string& out, const TableSchema& t, bool array,
                std::vector<const TableSchema*>& done) {
  if (std::find(done.begin(), done.end(), &t) != done.end()) return;
  done.push_back(&t);
  out += (array ? "[[" + t.name + "]]" : "[" + t.name + "]") + "\n";
  wrapped(out, plain(t.doc), "");
  out += "\n";
  key_text(out, t.keys);
  for (const auto& [name, keys] : t.variants) {
    out += fmt::format("  When {} = \"{}\":\n", t.discriminator, name);
    key_text(out, keys);
  }
  for (const auto& k : t.keys)
    if (k.sub) table_text(out, *k.sub, k.type == KeyType::TableArray, done);
  for (const auto& [name, keys] : t.variants)
    for (const auto& k : keys)
      if (k.sub) table_text(out, *k.sub, k.type == KeyType::TableArray, done);
}

}  // namespace

std::string schema_text() {
  std::string out =
      "crater scenario files: every key, its type, unit, default and range (SI units; TOML).\n"
      "Unknown keys and values out of range are errors (exit 2). Override any key with --set\n"
      "path.to.key=VALUE. The same as Markdown: crater schema --markdown "
      "(docs/scenario-format.md).\n\n";
  const TableSchema& root = scenario_schema();
  std::vector<const TableSchema*> done;
  for (const auto& k : root.keys)
    if (k.sub) table_text(out, *k.sub, k.type == KeyType::TableArray, done);
  return out;
}

std::string schema_markdown() {
  std::string md =
      "# Scenario file format\n\n"
      "<!-- Generated by `crater schema --markdown` from src/io/scenario/scenario_schema.cpp; "
      "a test keeps the two equal. Edit the schema, then run `make docs`. -->\n\n"
      "A scenario is a TOML file in SI units. Every key is listed below with its type, unit, "
      "default and allowed range. Unknown keys are errors; so are values of the wrong type or "
      "outside their range. Errors name the file, the line and the key, and `crater` exits "
      "with code 2 before any simulation work. Any key can be overridden from the command "
      "line with `--set path.to.key=VALUE` (VALUE in TOML syntax; array entries by index, "
      "e.g. `--set parts.0.spacing_m=0.01`, or by name, `--set parts.charge.spacing_m=0.01`).\n\n"
      "Vectors (`[number; dimension]`) have as many entries as `scenario.dimension`. In 2D "
      "(plane strain) masses and energies are per metre of depth.\n\n";
  const TableSchema& root = scenario_schema();
  std::vector<const TableSchema*> done;
  for (const auto& k : root.keys)
    if (k.sub) table_section(md, *k.sub, k.type == KeyType::TableArray, done);
  return md;
}

}  // namespace crater::io
