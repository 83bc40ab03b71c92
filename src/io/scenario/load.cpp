// Scenario loading (load.hpp): the file, --set overrides, [levels], validation against the
// schema, then the Builder (reader.hpp; its sections in read_*.cpp) and the hash.
#include "io/scenario/load.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>
#include <unistd.h>
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <string_view>

#include "core/file_kind.hpp"
#include "io/scenario/reader.hpp"
#include "io/scenario/schema.hpp"
#include "io/scenario/size_estimate.hpp"
#include "io/scenario/validate.hpp"

namespace crater::io {
namespace fs = std::filesystem;
namespace {

constexpr std::uintmax_t kMaxScenarioBytes = 4u << 20;  // a scenario is text, not data

std::string fnv1a_hex(const std::string& s) {
  std::uint64_t h = 14695981039346656037ull;
  for (unsigned char c : s) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return fmt::format("{:016x}", h);
}

// ---- --set overrides ------------------------------------------------------------------

std::vector<std::string> split_path(const std::string& p) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : p) {
    if (c == '.') {
      out.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  out.push_back(cur);
  return out;
}

void apply_override(toml::table& root, const std::string& arg) {
  const SourceLocation where{"--set " + arg, 0, 0};
  const auto eq = arg.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError(where, "", "expected --set dotted.key=VALUE");
  // Blanks around the '=' are allowed ("key = value", as in a TOML file).
  auto trim = [](std::string s) {
    const auto b = s.find_first_not_of(" \t");
    const auto e = s.find_last_not_of(" \t");
    return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
  };
  const std::string path = trim(arg.substr(0, eq));
  const std::string value = trim(arg.substr(eq + 1));
  const auto parts = split_path(path);
  for (const auto& s : parts)
    if (s.empty()) throw InputError(where, path, "empty segment in the key path");

  // The value in TOML syntax; a bare word is taken as a string (--set parts.0.method=sph).
  const bool bare_word =
      !value.empty() && value != "true" && value != "false" && value != "inf" && value != "nan" &&
      std::all_of(value.begin(), value.end(),
                  [](unsigned char ch) { return std::isalpha(ch) || ch == '_' || ch == '-'; });
  toml::table parsed;
  try {
    const std::string text = bare_word ? "v = \"" + value + "\"" : "v = " + value;
    parsed = toml::parse(std::string_view(text), "--set " + arg);
  } catch (const toml::parse_error& e) {
    throw InputError(where, path, "VALUE is not valid TOML: " + std::string(e.description()));
  }
  // Tables created on the way carry the argument as their source, for error messages.
  auto new_table = [&]() {
    toml::table doc = toml::parse(std::string_view("t = {}"), "--set " + arg);
    return std::move(*doc.get("t")->as_table());
  };

  toml::table* t = &root;
  for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
    toml::node* next = t->get(parts[i]);
    if (!next) {
      t->insert(parts[i], new_table());
      next = t->get(parts[i]);
    }
    if (auto* arr = next->as_array()) {
      // Element by index or by its `name` key.
      const std::string& sel = parts[++i];
      toml::node* el = nullptr;
      char* end = nullptr;
      const long idx = std::strtol(sel.c_str(), &end, 10);
      if (end && *end == '\0' && idx >= 0 && static_cast<std::size_t>(idx) < arr->size()) {
        el = arr->get(static_cast<std::size_t>(idx));
      } else {
        for (auto& e : *arr)
          if (auto* et = e.as_table())
            if (auto* n = et->get("name"); n && n->value<std::string>() == sel) el = &e;
      }
      if (!el || !el->is_table())
        throw InputError(where, path,
                         fmt::format("'{}' has no entry '{}' (use an index 0..{} or a name)",
                                     parts[i - 1], sel, arr->size() == 0 ? 0 : arr->size() - 1));
      if (i + 1 >= parts.size())
        throw InputError(where, path, "expected a key after the array entry");
      t = el->as_table();
      continue;
    }
    t = next->as_table();
    if (!t) throw InputError(where, path, "'" + parts[i] + "' is not a table");
  }
  if (parts.back().empty()) throw InputError(where, path, "empty key");
  t->insert_or_assign(parts.back(), std::move(*parsed.get("v")));
}

}  // namespace

namespace reader {

Config Builder::build() {
  Config c;
  c.file = file_;
  const SourceLocation top{file_, 1, 0};
  read_top(c, top);
  read_materials(c, top);
  read_parts(c, top);
  read_contacts(c, top);
  read_probes(c, top);
  read_gauges(c, top);
  errors_.throw_if_any(file_);
  for (auto& wmsg : c_warnings_)
    c.warnings.push_back(std::move(wmsg));
  return c;
}

// [scenario], [time], [output] and [domain].
void Builder::read_top(Config& c, const SourceLocation& top) {
  const auto& sc = table(root_, "scenario");
  c.name = str(sc, "name");
  c.description = str(sc, "description");
  c.dimension = static_cast<int>(sc.get("dimension")->as_integer()->get());
  c.end_time_s = num(sc, "end_time_s");
  const int dim = c.dimension;

  const auto& tt = table(root_, "time");
  c.time.safety_factor = num(tt, "safety_factor");
  c.time.fixed_dt_s = opt_num(tt, "fixed_dt_s");
  c.time.fixed_dt_where = loc(tt, "fixed_dt_s", top);
  c.time.min_dt_s = opt_num(tt, "min_dt_s");
  c.time.max_steps = tt.get("max_steps")->as_integer()->get();
  c.time.multi_rate = tt.get("multi_rate")->as_boolean()->get();
  c.time.multi_rate_max_ratio = tt.get("multi_rate_max_ratio")->as_integer()->get();
  if (c.time.multi_rate_max_ratio & (c.time.multi_rate_max_ratio - 1))
    error(loc(tt, "multi_rate_max_ratio", top), "time.multi_rate_max_ratio",
          fmt::format("expected a power of two (1, 2, 4, 8, ...), got {}",
                      c.time.multi_rate_max_ratio));
  if (c.time.multi_rate && c.time.fixed_dt_s)
    error(loc(tt, "multi_rate", top), "time.multi_rate",
          "multi-rate stepping takes each part's own stable step; unset time.fixed_dt_s or "
          "set multi_rate = false");
  c.time.energy_warn_error = num(tt, "energy_warn_error");
  c.time.energy_stop_error = num(tt, "energy_stop_error");
  if (c.time.energy_stop_error > 0 && c.time.energy_warn_error > c.time.energy_stop_error)
    error(loc(tt, "energy_warn_error", top), "time.energy_warn_error",
          fmt::format("expected at most time.energy_stop_error = {}, got {}",
                      c.time.energy_stop_error, c.time.energy_warn_error));

  const auto& ot = table(root_, "output");
  c.output.interval_s = opt_num(ot, "interval_s").value_or(c.end_time_s / 20);
  c.output.history_every = ot.get("history_every")->as_integer()->get();
  c.output.vtu = ot.get("vtu")->as_boolean()->get();
  c.output.checkpoint_every_steps = ot.get("checkpoint_every_steps")->as_integer()->get();
  c.output.checkpoint_every_s = num(ot, "checkpoint_every_s");
  c.output.checkpoint_keep = ot.get("checkpoint_keep")->as_integer()->get();
  c.output.checkpoint_at_end = ot.get("checkpoint_at_end")->as_boolean()->get();
  c.output.gauges_every_steps =
      static_cast<Index>(opt_num(ot, "gauges_every_steps").value_or(c.output.history_every));
  c.output.max_frames = ot.get("max_frames")->as_integer()->get();
  c.output.max_bytes = num(ot, "max_bytes");
  c.output.memory_limit_fraction = num(ot, "memory_limit_fraction");
  c.output.interval_where = loc(ot, "interval_s", top);
  c.output.interval_given = ot.get("interval_s") != nullptr;
  check_frame_count(c);
  c.output.vtu_encoding =
      str(ot, "vtu_encoding") == "base64" ? VtuEncoding::Base64 : VtuEncoding::Appended;
  c.output.pieces = str(ot, "pieces") == "ranks" ? FramePieces::Ranks : FramePieces::Gathered;
  if (c.output.interval_s > c.end_time_s)
    c.warnings.push_back(fmt::format(
        "output.interval_s = {} s exceeds scenario.end_time_s = {} s: only the first and "
        "last frames are written",
        c.output.interval_s, c.end_time_s));

  const auto& dt = table(root_, "domain");
  c.domain.bounded = dt.get("min_m") != nullptr && dt.get("max_m") != nullptr;
  if (c.domain.bounded) {
    c.domain.min_m = vec3(dt, "min_m");
    c.domain.max_m = vec3(dt, "max_m");
  } else {
    // FEM-only: nothing needs the box (read_parts refuses what does).
    constexpr Real inf = std::numeric_limits<Real>::infinity();
    c.domain.min_m = {-inf, -inf, -inf};
    c.domain.max_m = {inf, inf, inf};
    domain_ok_ = false;  // no overlap checks against it
    for (const char* k : {"min_m", "max_m"})
      if (dt.get(k))
        error(loc(dt, k, top), std::string("domain.") + k,
              "given alone: domain.min_m and domain.max_m go together");
  }
  c.domain.gravity_m_s2 = vec3(dt, "gravity_m_s2");
  c.domain.outflow = str(dt, "outflow") == "remove" ? Outflow::Remove : Outflow::Stop;
  c.domain.outflow_batch_steps = dt.get("outflow_batch_steps")->as_integer()->get();
  c.domain.balance_by_time = str(dt, "balance") == "time";
  const auto& sym = *dt.get("symmetry_planes")->as_array();
  c.domain.symmetry_planes =
      read_faces(sym, loc(dt, "symmetry_planes", top), "domain.symmetry_planes", dim);
  for (std::size_t j = 1; j < c.domain.symmetry_planes.size(); ++j)
    if (std::find(c.domain.symmetry_planes.begin(), c.domain.symmetry_planes.begin() + j,
                  c.domain.symmetry_planes[j]) != c.domain.symmetry_planes.begin() + j)
      error(where_of(*sym.get(j), loc(dt, "symmetry_planes", top)),
            fmt::format("domain.symmetry_planes[{}]", j),
            fmt::format("\"{}\" is listed twice",
                        kFaceNames[static_cast<int>(c.domain.symmetry_planes[j])]));
  if (!c.domain.bounded && !c.domain.symmetry_planes.empty())
    error(loc(dt, "symmetry_planes", top), "domain.symmetry_planes",
          "needs domain.min_m and domain.max_m: the planes are faces of the domain's box");
  for (int d = 0; d < dim && c.domain.bounded; ++d)
    if (!(c.domain.max_m[d] > c.domain.min_m[d])) {
      domain_ok_ = false;
      error(loc(dt, "max_m", top), "domain.max_m",
            fmt::format("expected every component above domain.min_m = {}, got {}",
                        vec_text(c.domain.min_m, dim), vec_text(c.domain.max_m, dim)));
      break;
    }
  domain_min_m_ = c.domain.min_m;
  domain_max_m_ = c.domain.max_m;
}

// VTU frames: end_time_s / interval_s of them (and the first; at most time.max_steps + 1).
// More than output.max_frames is a mistake in the interval (1e-15 s wrote a frame every
// step), not a wish.
void Builder::check_frame_count(const Config& c) {
  if (!c.output.vtu || !(c.output.interval_s > 0) || !(c.end_time_s > 0)) return;
  // A step ends on at most one frame: time.max_steps bounds the count as well.
  Real frames = std::ceil(c.end_time_s / c.output.interval_s) + 1;
  if (c.time.max_steps > 0) frames = std::min(frames, static_cast<Real>(c.time.max_steps) + 1);
  if (frames > static_cast<Real>(c.output.max_frames))
    error(c.output.interval_where, "output.interval_s",
          fmt::format("expected at most output.max_frames = {} VTU frames over "
                      "scenario.end_time_s = {} s (an interval of at least {:.4g} s); "
                      "interval_s = {} s gives {:.4g} frames (raise output.max_frames if "
                      "that many are wanted)",
                      c.output.max_frames, c.end_time_s,
                      c.end_time_s / static_cast<Real>(c.output.max_frames - 1),
                      c.output.interval_s, frames));
}

void ErrorList::throw_if_any(const std::string& file) {
  if (suppressed_ > 0)
    errors_.emplace_back(
        SourceLocation{file, 0, 0}, "",
        fmt::format("{} more errors not shown ({} are listed)", suppressed_, kMax));
  if (!errors_.empty()) throw InputErrors(std::move(errors_));
}

void report(ErrorList& errors, const toml::table& t, const SourceLocation& w,
            const std::string& key, const std::vector<materials::ConstantProblem>& problems) {
  for (const auto& p : problems) {
    if (p.key.empty())
      errors.add(w, key, p.message);
    else
      errors.add(loc(t, p.key.c_str(), w), key + "." + p.key, p.message);
  }
}

}  // namespace reader

namespace {

// Resolution levels: `[levels.<name>]` tables, each a list of overrides (`set`, in --set
// syntax) and a description. They are taken out of the table before validation; the chosen
// level's overrides apply before the command line's.
struct Level {
  std::string name, description;
  std::vector<std::pair<std::string, SourceLocation>> sets;
  std::uint32_t line = 0;
};

std::vector<Level> take_levels(toml::table& root, const std::string& file) {
  std::vector<Level> levels;
  toml::node* ln = root.get("levels");
  if (!ln) return levels;
  const SourceLocation top{file, 1, 0};
  const auto* lt = ln->as_table();
  if (!lt) throw InputError(where_of(*ln, top), "levels", "expected a table of [levels.<name>]");
  for (const auto& [k, v] : *lt) {
    const std::string key = "levels." + std::string(k.str());
    const auto* t = v.as_table();
    if (!t)
      throw InputError(where_of(v, top), key, "expected a table with `set` and `description`");
    Level l;
    l.name = std::string(k.str());
    for (const auto& [kk, vv] : *t) {
      const std::string sub = key + "." + std::string(kk.str());
      if (kk.str() == "description") {
        if (!vv.is_string()) throw InputError(where_of(vv, top), sub, "expected a string");
        l.description = vv.as_string()->get();
      } else if (kk.str() == "set") {
        const auto* arr = vv.as_array();
        if (!arr) throw InputError(where_of(vv, top), sub, "expected an array of \"key=VALUE\"");
        for (std::size_t i = 0; i < arr->size(); ++i) {
          const toml::node& e = *arr->get(i);
          if (!e.is_string())
            throw InputError(where_of(e, top), fmt::format("{}[{}]", sub, i),
                             "expected a string \"dotted.key=VALUE\" (--set syntax)");
          l.sets.emplace_back(e.as_string()->get(), where_of(e, top));
        }
      } else {
        throw InputError(where_of(vv, top), sub, "unknown key (a level has `set`, `description`)");
      }
    }
    l.line = v.source().begin.line;
    levels.push_back(std::move(l));
  }
  // In the file's order (a TOML table's keys come sorted).
  std::stable_sort(levels.begin(), levels.end(),
                   [](const Level& a, const Level& b) { return a.line < b.line; });
  root.erase("levels");
  return levels;
}

// The keys a run continued from a checkpoint may change (--resume DIR --set KEY=...): they set
// when it stops, what it checks and what it writes, never the state it continues from. The
// output interval is not among them: the frames' times are the interval's multiples, and a run
// lands a step on each (simulation.cpp).
constexpr std::array<std::pair<std::string_view, std::string_view>, 6> kRunControlKeys{{
    {"scenario", "end_time_s"},
    {"scenario", "description"},
    {"time", "max_steps"},
    {"time", "min_dt_s"},
    {"time", "energy_warn_error"},
    {"time", "energy_stop_error"},
}};

std::string state_hash(const toml::table& root, Real interval_s) {
  toml::table t = root;
  for (const auto& [table, key] : kRunControlKeys)
    if (auto* sub = t.get_as<toml::table>(table)) sub->erase(key);
  // The outputs but their interval, which counts as used (the default follows end_time_s).
  t.erase("output");
  t.insert("output_interval_s", interval_s);
  std::ostringstream os;
  os << t;
  return fnv1a_hex(os.str());
}

Config load_table(toml::table root, const std::string& file,
                  const std::vector<std::string>& overrides, const std::string& level) {
  const std::vector<Level> levels = take_levels(root, file);
  std::string known;
  for (const auto& l : levels)
    known += (known.empty() ? "" : ", ") + l.name;
  // "a,b": level a's overrides, then b's (a resolution and a variant: "medium,wide").
  for (std::size_t from = 0; !level.empty() && from <= level.size();) {
    const std::size_t comma = std::min(level.find(',', from), level.size());
    const std::string name = level.substr(from, comma - from);
    from = comma + 1;
    const auto it =
        std::find_if(levels.begin(), levels.end(), [&](const Level& l) { return l.name == name; });
    if (it == levels.end())
      throw InputError({"--level " + level, 0, 0}, "",
                       levels.empty()
                           ? fmt::format("the scenario {} defines no levels", file)
                           : fmt::format("no level '{}' in {} (levels: {})", name, file, known));
    for (const auto& [set, where] : it->sets) {
      try {
        apply_override(root, set);
      } catch (const InputError& e) {
        throw InputError(where, fmt::format("levels.{}.set", name), e.what());
      }
    }
  }
  for (const auto& o : overrides)
    apply_override(root, o);

  // The dimension is needed first: it sets the length of every vector key.
  int dim = 2;
  if (auto* sc = root.get("scenario"); sc && sc->is_table())
    if (auto* d = sc->as_table()->get("dimension"); d && d->is_integer()) {
      const auto v = d->as_integer()->get();
      if (v == 2 || v == 3) dim = static_cast<int>(v);
    }

  std::vector<InputError> errors;
  validate_table(root, scenario_schema(), "", dim, SourceLocation{file, 1, 0}, errors);
  if (!errors.empty()) throw InputErrors(std::move(errors));

  Config c = reader::Builder(root, file).build();
  estimate_part_sizes(root, c);
  c.level = level;
  for (const auto& l : levels)
    c.levels.push_back({l.name, l.description});
  std::ostringstream os;
  os << root;
  c.effective_toml = os.str();
  c.hash = fnv1a_hex(c.effective_toml);
  c.state_hash = state_hash(root, c.output.interval_s);
  return c;
}

toml::table parse_text(const std::string& text, const std::string& source_name) {
  try {
    return toml::parse(std::string_view(text), source_name);
  } catch (const toml::parse_error& e) {
    const auto& s = e.source();
    SourceLocation w{source_name, static_cast<int>(s.begin.line), static_cast<int>(s.begin.column)};
    throw InputError(w, "", "TOML syntax error: " + std::string(e.description()));
  }
}

}  // namespace

fs::path bundled_scenario_dir() {
  // Installed layout: <prefix>/bin/crater and <prefix>/share/crater/scenarios.
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path installed = exe.parent_path().parent_path() / "share/crater/scenarios";
    if (fs::is_directory(installed, ec)) return installed;
  }
  return fs::path(CRATER_SCENARIO_DIR);
}

std::vector<std::string> bundled_scenarios() {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(bundled_scenario_dir(), ec))
    if (e.path().extension() == ".toml") names.push_back(e.path().stem().string());
  std::sort(names.begin(), names.end());
  return names;
}

fs::path resolve_scenario(const std::string& path_or_name) {
  std::error_code ec;
  const fs::path p(path_or_name);
  if (fs::exists(p, ec)) {
    const std::string kind = not_a_regular_file(p);
    if (!kind.empty())
      throw InputError({path_or_name, 0, 0}, "",
                       "expected a scenario file (TOML text); '" + path_or_name + "' " + kind);
    return p;
  }
  if (path_or_name.find('/') == std::string::npos) {
    const fs::path bundled = bundled_scenario_dir() / (path_or_name + ".toml");
    if (fs::exists(bundled, ec)) return bundled;
  }
  std::string known;
  for (const auto& n : bundled_scenarios())
    known += (known.empty() ? "" : ", ") + n;
  throw InputError({path_or_name, 0, 0}, "",
                   "no such file, and no bundled scenario of that name (bundled: " + known + ")");
}

Config load_scenario(const std::string& path_or_name, const std::vector<std::string>& overrides,
                     const std::string& level) {
  const fs::path path = resolve_scenario(path_or_name);
  std::error_code ec;
  const auto size = fs::file_size(path, ec);
  if (ec) throw InputError({path.string(), 0, 0}, "", "cannot read the file: " + ec.message());
  if (size > kMaxScenarioBytes)
    throw InputError({path.string(), 0, 0}, "",
                     fmt::format("file is {} bytes; a scenario file is at most {} bytes", size,
                                 kMaxScenarioBytes));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError({path.string(), 0, 0}, "", "cannot open the file");
  std::ostringstream ss;
  ss << in.rdbuf();
  return load_scenario_text(ss.str(), path.string(), overrides, level);
}

Config load_scenario_text(const std::string& text, const std::string& source_name,
                          const std::vector<std::string>& overrides, const std::string& level) {
  if (text.find('\0') != std::string::npos)
    throw InputError({source_name, 0, 0}, "", "expected a text (TOML) file, found a NUL byte");
  return load_table(parse_text(text, source_name), source_name, overrides, level);
}

}  // namespace crater::io
