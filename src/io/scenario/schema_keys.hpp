// The words the schema's tables are written in: a key of a type, with its unit and help text,
// then what it takes (required, a default, a range). scenario_schema.cpp and the material
// laws' entries (material_laws.cpp) state every key with them.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "io/scenario/schema.hpp"

namespace crater::io::keys {

inline KeySchema real(std::string name, std::string unit, std::string doc) {
  KeySchema k;
  k.name = std::move(name);
  k.type = KeyType::Real;
  k.unit = std::move(unit);
  k.doc = std::move(doc);
  return k;
}
inline KeySchema required(KeySchema k) {
  k.required = true;
  return k;
}
inline KeySchema with_default(KeySchema k, std::string toml_literal) {
  k.default_toml = std::move(toml_literal);
  return k;
}
inline KeySchema at_least(KeySchema k, double v) {
  k.min = v;
  return k;
}
inline KeySchema positive(KeySchema k) {
  k.min = 0;
  k.min_exclusive = true;
  return k;
}
inline KeySchema at_most(KeySchema k, double v) {
  k.max = v;
  return k;
}
inline KeySchema of_type(KeySchema k, KeyType t) {
  k.type = t;
  return k;
}
inline KeySchema choice(std::string name, std::vector<std::string> choices, std::string doc) {
  KeySchema k;
  k.name = std::move(name);
  k.type = KeyType::Choice;
  k.choices = std::move(choices);
  k.doc = std::move(doc);
  return k;
}
inline KeySchema choice_list(std::string name, std::vector<std::string> choices, std::string doc) {
  KeySchema k = choice(std::move(name), std::move(choices), std::move(doc));
  k.type = KeyType::ChoiceList;
  return k;
}
inline KeySchema text(std::string name, std::string doc) {
  KeySchema k;
  k.name = std::move(name);
  k.type = KeyType::String;
  k.doc = std::move(doc);
  return k;
}
inline KeySchema vec(std::string name, std::string unit, std::string doc) {
  return of_type(real(std::move(name), std::move(unit), std::move(doc)), KeyType::RealVector);
}
/// A whole number (a count, a seed, a dimension).
inline KeySchema whole(std::string name, std::string doc) {
  return of_type(real(std::move(name), "1", std::move(doc)), KeyType::Integer);
}
/// true or false.
inline KeySchema flag(std::string name, std::string doc) {
  return of_type(real(std::move(name), "", std::move(doc)), KeyType::Bool);
}
inline KeySchema repeats_allowed(KeySchema k) {
  k.repeats = true;
  return k;
}
inline KeySchema absent_means_unset(KeySchema k) {
  k.absent_means_unset = true;
  return k;
}
inline KeySchema sub(std::string name, KeyType t, const TableSchema& s, std::string doc) {
  KeySchema k;
  k.name = std::move(name);
  k.type = t;
  k.sub = &s;
  k.doc = std::move(doc);
  return k;
}

}  // namespace crater::io::keys
