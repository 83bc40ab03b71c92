// The output fields of an FEM part (its VTU point and cell data, the fields [[gauges]] read),
// by name and unit.
#pragma once

#include "fields/field_set.hpp"

namespace crater::fem {

// Nodes.
inline const fields::FieldInfo kVelocityInfo{"velocity", "m/s", fields::kOutput};
inline const fields::FieldInfo kDisplacementInfo{"displacement", "m", fields::kOutput};
inline const fields::FieldInfo kNodeMassInfo{"node_mass", "kg", fields::kOutput};
inline const fields::FieldInfo kInternalForceInfo{"internal_force", "N", fields::kOutput};
inline const fields::FieldInfo kReactionForceInfo{"reaction_force", "N", fields::kOutput};
inline const fields::FieldInfo kContactForceInfo{"contact_force", "N", fields::kOutput};

// Elements.
inline const fields::FieldInfo kVonMisesInfo{"von_mises", "Pa", fields::kOutput};
inline const fields::FieldInfo kPressureInfo{"pressure", "Pa", fields::kOutput};
inline const fields::FieldInfo kPlasticStrainInfo{"plastic_strain", "1", fields::kOutput};
inline const fields::FieldInfo kDensityInfo{"density", "kg/m^3", fields::kOutput};
inline const fields::FieldInfo kDamageInfo{"damage", "1", fields::kOutput};
inline const fields::FieldInfo kPlasticVolumetricStrainInfo{"plastic_volumetric_strain", "1",
                                                            fields::kOutput};
inline const fields::FieldInfo kErodedInfo{"eroded", "1", fields::kOutput};
inline const fields::FieldInfo kTemperatureInfo{"temperature", "K", fields::kOutput};

}  // namespace crater::fem
