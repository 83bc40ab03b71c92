#include "io/scenario/validate.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>

namespace crater::io {
namespace {

std::string type_name(KeyType t, int dimension) {
  if (t == KeyType::RealVector) return fmt::format("an array of {} numbers", dimension);
  return words_of(t).expected;
}

std::string node_type_name(const toml::node& n) {
  switch (n.type()) {
    case toml::node_type::none:
      return "nothing";
    case toml::node_type::floating_point:
      return "a number";  // toml++ says "floating-point"
    default: {
      // toml++'s own words: table, array, string, integer, boolean, date, time, date-time.
      std::ostringstream os;
      os << n.type();
      const std::string word = os.str();
      return (word.front() == 'a' || word.front() == 'i' ? "an " : "a ") + word;
    }
  }
}

std::string range_text(const KeySchema& k) {
  if (k.min && k.max)
    return fmt::format("{} {} and <= {}", k.min_exclusive ? ">" : ">=", *k.min, *k.max);
  if (k.min) return fmt::format("{} {}", k.min_exclusive ? ">" : ">=", *k.min);
  if (k.max) return fmt::format("<= {}", *k.max);
  return "";
}

bool in_range(const KeySchema& k, double v) {
  if (!std::isfinite(v)) return false;
  if (k.min && (k.min_exclusive ? !(v > *k.min) : !(v >= *k.min))) return false;
  if (k.max && !(v <= *k.max)) return false;
  return true;
}

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (std::size_t i = 0; i < v.size(); ++i)
    s += (i ? ", " : "") + ("\"" + v[i] + "\"");
  return s;
}

// Closest known key (by edit distance) for "did you mean" hints.
std::string closest(const std::string& name, const std::vector<const KeySchema*>& keys) {
  auto dist = [](const std::string& a, const std::string& b) {
    std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j)
      prev[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
      cur[0] = i;
      for (std::size_t j = 1; j <= b.size(); ++j)
        cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] != b[j - 1])});
      std::swap(prev, cur);
    }
    return prev[b.size()];
  };
  std::string best;
  std::size_t best_d = 4;
  for (const auto* k : keys) {
    const std::size_t d = dist(name, k->name);
    if (d < best_d) best_d = d, best = k->name;
  }
  return best;
}

using Errors = std::vector<InputError>;

void check_number(const toml::node& n, const KeySchema& k, const std::string& kp,
                  const SourceLocation& w, Errors& errors) {
  double v = 0;
  if (auto* f = n.as_floating_point())
    v = f->get();
  else if (auto* i = n.as_integer())
    v = static_cast<double>(i->get());
  else {
    errors.emplace_back(w, kp, "expected a number, got " + node_type_name(n));
    return;
  }
  if (!in_range(k, v)) {
    errors.emplace_back(
        w, kp,
        fmt::format("expected a finite number{}{}{}, got {}", range_text(k).empty() ? "" : " ",
                    range_text(k), k.unit.empty() || k.unit == "1" ? "" : " [" + k.unit + "]", v));
  }
}

void check_integer(const toml::node& node, const KeySchema& k, const std::string& key_path,
                   const SourceLocation& where, Errors& errors) {
  auto* i = node.as_integer();
  if (!i) {
    errors.emplace_back(where, key_path, "expected an integer, got " + node_type_name(node));
    return;
  }
  if (!in_range(k, static_cast<double>(i->get())))
    errors.emplace_back(where, key_path,
                        fmt::format("expected an integer{}{}, got {}",
                                    range_text(k).empty() ? "" : " ", range_text(k), i->get()));
}

void check_choice(const toml::node& node, const KeySchema& k, const std::string& key_path,
                  const SourceLocation& where, Errors& errors) {
  auto* s = node.as_string();
  if (!s) {
    errors.emplace_back(where, key_path,
                        "expected one of " + join(k.choices) + ", got " + node_type_name(node));
    return;
  }
  bool ok = false;
  for (const auto& c : k.choices)
    ok = ok || (c == s->get());
  if (!ok)
    errors.emplace_back(where, key_path,
                        "expected one of " + join(k.choices) + ", got \"" + s->get() + "\"");
}

// StringArray: distinct strings; ChoiceList: distinct strings, each one of the choices.
void check_string_list(const toml::node& node, const KeySchema& k, const std::string& key_path,
                       const SourceLocation& where, Errors& errors) {
  const bool choices = k.type == KeyType::ChoiceList;
  auto* a = node.as_array();
  if (!a) {
    errors.emplace_back(where, key_path,
                        (choices ? "expected an array of strings from " + join(k.choices)
                                 : std::string("expected an array of strings")) +
                            ", got " + node_type_name(node));
    return;
  }
  std::set<std::string> seen;
  for (std::size_t i = 0; i < a->size(); ++i) {
    auto* s = a->get(i)->as_string();
    const SourceLocation w = where_of(*a->get(i), where);
    const std::string kp = fmt::format("{}[{}]", key_path, i);
    if (!s) {
      errors.emplace_back(
          w, kp,
          (choices ? "expected one of " + join(k.choices) : std::string("expected a string")) +
              ", got " + node_type_name(*a->get(i)));
      continue;
    }
    if (choices && std::find(k.choices.begin(), k.choices.end(), s->get()) == k.choices.end())
      errors.emplace_back(w, kp,
                          "expected one of " + join(k.choices) + ", got \"" + s->get() + "\"");
    else if (!seen.insert(s->get()).second && !k.repeats)
      errors.emplace_back(w, kp, "\"" + s->get() + "\" is listed twice");
  }
}

// RealVector (dimension entries) and RealArray (any number).
void check_real_list(const toml::node& node, const KeySchema& k, const std::string& key_path,
                     int dimension, const SourceLocation& where, Errors& errors) {
  auto* a = node.as_array();
  if (!a) {
    errors.emplace_back(
        where, key_path,
        "expected " + type_name(k.type, dimension) + ", got " + node_type_name(node));
    return;
  }
  if (k.type == KeyType::RealVector && static_cast<int>(a->size()) != dimension) {
    errors.emplace_back(where, key_path,
                        fmt::format("expected {} (scenario.dimension = {}), got {} entries",
                                    type_name(k.type, dimension), dimension, a->size()));
    return;
  }
  for (std::size_t i = 0; i < a->size(); ++i)
    check_number(*a->get(i), k, fmt::format("{}[{}]", key_path, i), where_of(*a->get(i), where),
                 errors);
}

void check_value(toml::node& node, const KeySchema& k, const std::string& key_path, int dimension,
                 const SourceLocation& where, Errors& errors) {
  auto expect = [&](const std::string& what) { errors.emplace_back(where, key_path, what); };
  switch (k.type) {
    case KeyType::Real:
      check_number(node, k, key_path, where, errors);
      break;
    case KeyType::Integer:
      check_integer(node, k, key_path, where, errors);
      break;
    case KeyType::Bool:
      if (!node.is_boolean()) expect("expected true or false, got " + node_type_name(node));
      break;
    case KeyType::String:
      if (!node.is_string()) expect("expected a string, got " + node_type_name(node));
      break;
    case KeyType::Choice:
      check_choice(node, k, key_path, where, errors);
      break;
    case KeyType::StringArray:
    case KeyType::ChoiceList:
      check_string_list(node, k, key_path, where, errors);
      break;
    case KeyType::RealVector:
    case KeyType::RealArray:
      check_real_list(node, k, key_path, dimension, where, errors);
      break;
    case KeyType::Table: {
      auto* t = node.as_table();
      if (!t) {
        expect("expected a table, got " + node_type_name(node));
        break;
      }
      validate_table(*t, *k.sub, key_path, dimension, where, errors);
      break;
    }
    case KeyType::TableArray: {
      auto* a = node.as_array();
      if (!a || !a->is_array_of_tables()) {
        expect("expected an array of tables ([[" + key_path + "]]), got " + node_type_name(node));
        break;
      }
      for (std::size_t i = 0; i < a->size(); ++i) {
        auto* t = a->get(i)->as_table();
        validate_table(*t, *k.sub, fmt::format("{}[{}]", key_path, i), dimension,
                       where_of(*t, where), errors);
      }
      break;
    }
  }
}

void insert_default(toml::table& table, const KeySchema& k) {
  // Defaults are TOML literals; parse "v = <literal>" and move the value in.
  const std::string text = "v = " + *k.default_toml;
  auto parsed = toml::parse(std::string_view(text), std::string_view("<default>"));
  table.insert(k.name, std::move(*parsed.get("v")));
}

}  // namespace

SourceLocation where_of(const toml::node& node, const SourceLocation& fallback) {
  const auto& src = node.source();
  if (!src.begin || (src.path && *src.path == "<default>")) return fallback;
  SourceLocation w;
  w.file = src.path ? *src.path : fallback.file;
  // Values from --set are named by the argument itself; a line inside it means nothing.
  const bool from_set = w.file.rfind("--set ", 0) == 0;
  w.line = from_set ? 0 : static_cast<int>(src.begin.line);
  w.column = from_set ? 0 : static_cast<int>(src.begin.column);
  return w;
}

void validate_table(toml::table& table, const TableSchema& schema, const std::string& path,
                    int dimension, const SourceLocation& table_where,
                    std::vector<InputError>& errors) {
  std::vector<const KeySchema*> keys;
  for (const auto& k : schema.keys)
    keys.push_back(&k);

  bool variant_known = true;
  if (!schema.discriminator.empty()) {
    // The discriminator selects the variant's keys; it is validated as one of the variants.
    // When it is missing or invalid, only that is reported: the other keys cannot be judged.
    const toml::node* d = table.get(schema.discriminator);
    variant_known = false;
    if (d && d->is_string()) {
      auto it = schema.variants.find(d->as_string()->get());
      if (it != schema.variants.end()) {
        for (const auto& k : it->second)
          keys.push_back(&k);
        variant_known = true;
      }
    }
  }

  auto key_path = [&](const std::string& name) { return path.empty() ? name : path + "." + name; };

  // Unknown keys are errors, with a hint when a known key is close.
  for (auto&& [name, node] : table) {
    if (!variant_known) break;
    const std::string n(name.str());
    bool known = false;
    for (const auto* k : keys)
      known = known || k->name == n;
    if (!known) {
      std::string what = "unknown key";
      const std::string hint = closest(n, keys);
      if (!hint.empty())
        what += "; did you mean '" + hint + "'?";
      else {
        what += " (known keys here: ";
        for (std::size_t i = 0; i < keys.size(); ++i)
          what += (i ? ", " : "") + keys[i]->name;
        what += ")";
      }
      errors.emplace_back(where_of(node, table_where), key_path(n), what);
    }
  }

  for (const auto* k : keys) {
    toml::node* node = table.get(k->name);
    if (!node) {
      if (k->required) {
        errors.emplace_back(table_where, key_path(k->name),
                            "missing required key (" + type_name(k->type, dimension) +
                                (k->unit.empty() || k->unit == "1" ? "" : ", in " + k->unit) + ")" +
                                (path.empty() ? "" : " in [" + path + "]"));
        continue;
      }
      if (k->default_toml) {
        insert_default(table, *k);
        node = table.get(k->name);
      } else if (k->type == KeyType::Table && !k->absent_means_unset) {
        // Optional sub-tables are created so that their own defaults apply.
        table.insert(k->name, toml::table{});
        node = table.get(k->name);
      } else {
        continue;  // optional, no default: absent means "not set"
      }
    }
    check_value(*node, *k, key_path(k->name), dimension, where_of(*node, table_where), errors);
  }
}

}  // namespace crater::io
