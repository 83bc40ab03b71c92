// The contact laws a DEM part can take: one registration line per law (its header in laws/
// answers what the part asks, law_binding.hpp). The part holds the laws of its
// settings.contact as a ContactLaws value, chosen once, and its pair loop is a template on the
// law (std::visit over that value), so no contact branches on the law; nothing in the part
// names a law. Adding a law: its header in laws/ (Params, prepare, finish and the part's
// questions), its ContactLawKind value (settings.hpp, set by the scenario reader from the
// law's keys), and its line in ContactLawRegistry below (docs/architecture.md, "How to add a
// DEM contact law").
#pragma once

#include <optional>
#include <stdexcept>
#include <variant>

#include "dem/laws/hertz_mindlin.hpp"
#include "dem/laws/law_binding.hpp"
#include "dem/laws/linear_spring.hpp"
#include "dem/settings.hpp"

namespace crater::dem {

/// One registration: the scenario's ContactLawKind value of a law, and the law.
template <ContactLawKind Kind, PartContactLaw Law>
struct LawEntry {
  static constexpr ContactLawKind kind = Kind;
  using Type = Law;
};

/// The laws of a registry, as one value: the law pair of whichever law a part takes.
template <class... Entry>
struct LawRegistry {
  using Laws = std::variant<LawPair<typename Entry::Type>...>;

  /// The law pair of `dem.contact`, from the part's settings and its grain material.
  static Laws make(const Settings& dem, const GranularMaterial& grain) {
    std::optional<Laws> laws;
    ((dem.contact == Entry::kind ? void(laws.emplace(Entry::Type::part_laws(dem, grain))) : void()),
     ...);
    if (!laws) throw std::logic_error("dem: a contact law without a registry entry");
    return *laws;
  }
};

/// The registry.
using ContactLawRegistry = LawRegistry<LawEntry<ContactLawKind::HertzMindlin, HertzMindlin>,
                                       LawEntry<ContactLawKind::LinearSpring, LinearSpring>>;

/// The grain-grain and grain-wall parameters of the part's law (ContactLawRegistry::make).
using ContactLaws = ContactLawRegistry::Laws;

}  // namespace crater::dem
