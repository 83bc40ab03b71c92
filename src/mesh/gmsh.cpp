#include "mesh/gmsh.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <charconv>
#include <climits>
#include <cmath>
#include <fstream>
#include <map>
#include <system_error>
#include <tuple>
#include <utility>

#include "core/error.hpp"
#include "core/file_kind.hpp"

namespace crater::mesh {
namespace {

// Lines are counted in an int (SourceLocation), so the text stays well below 2^31 bytes.
constexpr std::uintmax_t kMaxTextBytes = 2'000'000'000;
constexpr std::size_t kMaxPhysicalNameLength = 127;  // the MSH 4.1 limit
constexpr std::int64_t kMaxEntities = 1'000'000;     // per file, all dimensions together
constexpr std::int64_t kMaxPhysicalNames = 1'000'000;
constexpr std::int64_t kMaxTagsPerEntity = 100'000;  // physical or bounding tags of one entity

struct ElementType {
  int code;
  int dim;
  int nodes;
  const char* name;
};
constexpr ElementType kSupportedTypes[] = {
    {1, 1, 2, "2-node line"},        {2, 2, 3, "3-node triangle"},   {3, 2, 4, "4-node quadrangle"},
    {4, 3, 4, "4-node tetrahedron"}, {5, 3, 8, "8-node hexahedron"}, {15, 0, 1, "1-node point"},
};

const ElementType* supported_type(std::int64_t code) {
  for (const auto& t : kSupportedTypes)
    if (t.code == code) return &t;
  return nullptr;
}

// Why a Gmsh element type is refused, and what to do instead.
std::string unsupported_type_message(std::int64_t code) {
  struct Named {
    int code;
    const char* name;
  };
  static constexpr Named kHigherOrder[] = {
      {8, "3-node second-order line"},         {9, "6-node second-order triangle"},
      {10, "9-node second-order quadrangle"},  {11, "10-node second-order tetrahedron"},
      {12, "27-node second-order hexahedron"}, {13, "18-node second-order prism"},
      {14, "14-node second-order pyramid"},    {16, "8-node second-order quadrangle"},
      {17, "20-node second-order hexahedron"}, {18, "15-node second-order prism"},
      {19, "13-node second-order pyramid"},
  };
  for (const auto& t : kHigherOrder)
    if (t.code == code)
      return fmt::format(
          "element type {} ({}) is not supported: use first-order elements (Mesh.ElementOrder = "
          "1)",
          code, t.name);
  if (code == 6 || code == 7)
    return fmt::format(
        "element type {} ({}) is not supported: mesh the volume with hexahedra or tetrahedra only",
        code, code == 6 ? "6-node prism" : "5-node pyramid");
  return fmt::format(
      "element type {} is not supported: use first-order elements (Mesh.ElementOrder = 1) of "
      "types 1 (line), 2 (triangle), 3 (quadrangle), 4 (tetrahedron), 5 (hexahedron) or 15 "
      "(point)",
      code);
}

bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f';
}

// A token as it may appear in a message: short, printable.
std::string shown(std::string_view s) {
  constexpr std::size_t kMax = 40;
  std::string out;
  for (std::size_t i = 0; i < s.size() && i < kMax; ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    out += (c >= 0x20 && c < 0x7f) ? static_cast<char>(c) : '?';
  }
  if (s.size() > kMax) out += "...";
  return out;
}

struct Token {
  std::string_view text;  // empty at the end of the text
  int line = 0;
  int column = 0;
  bool eof() const { return text.empty(); }
};

struct Quoted {
  enum Status { kOk, kMissing, kUnterminated } status = kMissing;
  std::string_view value;
  int line = 0;
  int column = 0;
};

// Whitespace-separated tokens with their line and column (both from 1).
class Cursor {
 public:
  explicit Cursor(std::string_view text) : text_(text) {}

  Token next() {
    skip_space();
    const std::size_t start = pos_;
    const int col = column();
    while (pos_ < text_.size() && !is_space(text_[pos_]))
      ++pos_;
    return {text_.substr(start, pos_ - start), line_, col};
  }
  Token peek() const {
    Cursor c = *this;
    return c.next();
  }

  // A double-quoted string that must start and end on the current line.
  Quoted quoted() {
    while (pos_ < text_.size() &&
           (text_[pos_] == ' ' || text_[pos_] == '\t' || text_[pos_] == '\r'))
      ++pos_;
    Quoted q;
    q.line = line_;
    q.column = column();
    if (pos_ >= text_.size() || text_[pos_] != '"') return q;
    const std::size_t start = ++pos_;
    while (pos_ < text_.size() && text_[pos_] != '"' && text_[pos_] != '\n')
      ++pos_;
    if (pos_ >= text_.size() || text_[pos_] != '"') {
      q.status = Quoted::kUnterminated;
      return q;
    }
    q.value = text_.substr(start, pos_ - start);
    ++pos_;
    q.status = Quoted::kOk;
    return q;
  }

  int line() const { return line_; }

 private:
  void skip_space() {
    while (pos_ < text_.size() && is_space(text_[pos_])) {
      if (text_[pos_] == '\n') {
        ++line_;
        line_start_ = pos_ + 1;
      }
      ++pos_;
    }
  }
  int column() const { return static_cast<int>(pos_ - line_start_ + 1); }

  std::string_view text_;
  std::size_t pos_ = 0;
  std::size_t line_start_ = 0;
  int line_ = 1;
};

// The elements of one $Elements block, node tags already turned into node indices.
struct RawBlock {
  int entity_dim = 0;
  int entity_tag = 0;
  const ElementType* type = nullptr;
  int header_line = 0;
  int header_column = 0;
  std::vector<std::int64_t> connectivity;
  std::vector<int> lines;
};

class Parser {
 public:
  Parser(std::string_view text, const std::string& source) : cur_(text), source_(source) {}

  GmshMesh run() {
    const Token first = cur_.next();
    if (first.eof()) fail(1, 0, "the file is empty; a Gmsh mesh starts with $MeshFormat");
    if (first.text != "$MeshFormat")
      fail(first, fmt::format("not a Gmsh .msh file: it must start with $MeshFormat, found '{}'",
                              shown(first.text)));
    read_mesh_format(first);

    for (Token t = cur_.next(); !t.eof(); t = cur_.next()) {
      if (t.text.front() != '$')
        fail(t, fmt::format("expected a section header such as $Nodes, found '{}'", shown(t.text)));
      if (t.text == "$MeshFormat") fail(t, "a second $MeshFormat section");
      if (t.text == "$PhysicalNames")
        read_physical_names(t);
      else if (t.text == "$Entities")
        read_entities(t);
      else if (t.text == "$Nodes")
        read_nodes(t);
      else if (t.text == "$Elements")
        read_elements(t);
      else if (t.text == "$PartitionedEntities")
        fail(t,
             "partitioned meshes are not supported ($PartitionedEntities); save the mesh "
             "unpartitioned");
      else
        skip_section(t);
    }
    return assemble();
  }

 private:
  // ---- errors and tokens ------------------------------------------------------------------

  [[noreturn]] void fail(int line, int column, std::string what) const {
    throw InputError(SourceLocation{source_, line, column}, section_, std::move(what));
  }
  [[noreturn]] void fail(const Token& t, std::string what) const {
    fail(t.line, t.column, std::move(what));
  }

  void begin_section(const Token& header) {
    section_ = std::string(header.text);
    section_line_ = header.line;
    expect_line_end(header.line, header.text);
  }

  // The next token; the end of the text here means the file was cut short.
  Token expect(std::string_view what) {
    const Token t = cur_.next();
    if (t.eof())
      fail(t, fmt::format("the file ends inside {} (begun on line {}) where {} was expected: "
                          "the file is truncated",
                          section_, section_line_, what));
    return t;
  }

  // The next token, which must be on `line` (records of the format are single lines).
  Token expect_on_line(int line, std::string_view what) {
    const Token t = expect(what);
    if (t.line != line) fail(line, 0, fmt::format("the line ends where {} was expected", what));
    return t;
  }

  // Nothing more may follow on `line`.
  void expect_line_end(int line, std::string_view after) {
    const Token t = cur_.peek();
    if (!t.eof() && t.line == line)
      fail(t, fmt::format("unexpected '{}' after {}", shown(t.text), after));
  }

  std::string found(const Token& t) const {
    std::string s = fmt::format("found '{}'", shown(t.text));
    if (t.text.front() == '$')
      s += fmt::format(": the section ends before the entries announced on line {}", count_line_);
    return s;
  }

  std::int64_t to_int(const Token& t, std::string_view what) const {
    std::int64_t v = 0;
    const char* b = t.text.data();
    const char* e = b + t.text.size();
    const auto [p, ec] = std::from_chars(b, e, v);
    if (ec == std::errc::result_out_of_range)
      fail(t, fmt::format("{} '{}' is out of range", what, shown(t.text)));
    if (ec != std::errc() || p != e)
      fail(t, fmt::format("expected {} (an integer), {}", what, found(t)));
    return v;
  }

  int to_int32(const Token& t, std::string_view what) const {
    const std::int64_t v = to_int(t, what);
    if (v < INT_MIN || v > INT_MAX)
      fail(t, fmt::format("{} '{}' is out of range", what, shown(t.text)));
    return static_cast<int>(v);
  }

  // A count in [0, max]; `too_many` says why the limit is there.
  std::int64_t to_count(const Token& t, std::string_view what, std::int64_t max,
                        std::string_view too_many) const {
    const std::int64_t v = to_int(t, what);
    if (v < 0) fail(t, fmt::format("{} must not be negative, found {}", what, v));
    if (v > max) fail(t, fmt::format("{} is {}: {}", what, v, too_many));
    return v;
  }

  int to_dim(const Token& t, std::string_view what) const {
    const std::int64_t v = to_int(t, what);
    if (v < 0 || v > 3) fail(t, fmt::format("{} must be 0, 1, 2 or 3, found {}", what, v));
    return static_cast<int>(v);
  }

  double to_double(const Token& t, std::string_view what) const {
    std::string_view s = t.text;
    if (s.size() > 1 && s[0] == '+' && s[1] != '-' && s[1] != '+') s.remove_prefix(1);
    double v = 0;
    const char* b = s.data();
    const char* e = b + s.size();
    const auto [p, ec] = std::from_chars(b, e, v);
    if (ec == std::errc::result_out_of_range)
      fail(t, fmt::format("{} '{}' is not a finite number", what, shown(t.text)));
    if (ec != std::errc() || p != e)
      fail(t, fmt::format("expected {} (a number), {}", what, found(t)));
    return v;
  }

  void expect_section_end(std::string_view end) {
    const Token t = cur_.next();
    if (t.eof())
      fail(t, fmt::format("the file ends before {}: the {} section begun on line {} is not closed "
                          "(truncated file?)",
                          end, section_, section_line_));
    if (t.text != end) {
      if (t.text.front() == '$')
        fail(t, fmt::format("expected {} to close the {} section begun on line {}, found '{}'", end,
                            section_, section_line_, shown(t.text)));
      fail(t, fmt::format("expected {}, found '{}': the section holds more entries than announced "
                          "on line {}",
                          end, shown(t.text), count_line_));
    }
    section_.clear();
  }

  void skip_section(const Token& header) {
    const std::string_view name = header.text.substr(1);
    if (name.empty() || name.substr(0, 3) == "End")
      fail(header, fmt::format("'{}' without an opening section header", shown(header.text)));
    const std::string end = "$End" + std::string(name);
    for (Token t = cur_.next(); t.text != end; t = cur_.next())
      if (t.eof())
        fail(header, fmt::format("the section {} begun here has no {}: the file is truncated",
                                 shown(header.text), shown(end)));
  }

  // ---- sections ----------------------------------------------------------------------------

  void read_mesh_format(const Token& header) {
    begin_section(header);
    const Token version = expect("the MSH version");
    if (version.text != "4.1") {
      const double v = to_double(version, "the MSH version");
      if (v >= 2.0 && v < 3.0)
        fail(version, fmt::format("MSH {} is not supported; export MSH 4.1 (Gmsh: File > Export, "
                                  "Version 4 ASCII; or -format msh41)",
                                  shown(version.text)));
      if (v != 4.1)
        fail(version, fmt::format("MSH version {} is not supported; export MSH 4.1 (Gmsh: File > "
                                  "Export, Version 4 ASCII; or -format msh41)",
                                  shown(version.text)));
    }
    const Token type = expect_on_line(version.line, "the file type (0 for ASCII)");
    const std::int64_t file_type = to_int(type, "the file type");
    if (file_type == 1)
      fail(type,
           "binary .msh is not supported; save as ASCII (Gmsh: Mesh.Binary = 0, or -format msh41 "
           "without -bin)");
    if (file_type != 0)
      fail(type, fmt::format("the file type must be 0 (ASCII), found {}", file_type));
    const Token size = expect_on_line(version.line, "the data size");
    to_count(size, "the data size", 64, "expected the size of size_t (8)");
    expect_line_end(version.line, "the data size");
    expect_section_end("$EndMeshFormat");
  }

  void read_physical_names(const Token& header) {
    begin_section(header);
    if (physical_names_line_ == 0) physical_names_line_ = header.line;
    const Token n_tok = expect("the number of physical names");
    count_line_ = n_tok.line;
    const std::int64_t n =
        to_count(n_tok, "the number of physical names", kMaxPhysicalNames, "too many");
    expect_line_end(n_tok.line, "the number of physical names");
    for (std::int64_t i = 0; i < n; ++i) {
      const Token d = expect("the dimension of a physical group");
      const int dim = to_dim(d, "the dimension of a physical group");
      const int tag = to_int32(expect_on_line(d.line, "a physical tag"), "the physical tag");
      const Quoted q = cur_.quoted();
      if (q.status == Quoted::kMissing)
        fail(q.line, q.column, "expected the physical name in double quotes");
      if (q.status == Quoted::kUnterminated)
        fail(q.line, q.column,
             "unterminated quotes: the physical name must end with \" on the same line");
      if (q.value.size() > kMaxPhysicalNameLength)
        fail(q.line, q.column,
             fmt::format("the physical name is {} characters long; at most {} are allowed",
                         q.value.size(), kMaxPhysicalNameLength));
      expect_line_end(d.line, "the physical name");
      if (!physical_names_.emplace(std::pair{dim, tag}, std::string(q.value)).second)
        fail(d, fmt::format("physical group {} of dimension {} is named twice", tag, dim));
    }
    expect_section_end("$EndPhysicalNames");
  }

  void read_entities(const Token& header) {
    begin_section(header);
    const Token first = expect("the number of points");
    count_line_ = first.line;
    static constexpr const char* kCounts[4] = {"the number of points", "the number of curves",
                                               "the number of surfaces", "the number of volumes"};
    std::int64_t counts[4] = {};
    for (int d = 0; d < 4; ++d) {
      const Token t = d == 0 ? first : expect_on_line(first.line, kCounts[d]);
      counts[d] = to_count(t, kCounts[d], kMaxEntities, "too many entities");
    }
    expect_line_end(first.line, "the four entity counts");
    for (int dim = 0; dim < 4; ++dim) {
      for (std::int64_t i = 0; i < counts[dim]; ++i) {
        if (static_cast<std::int64_t>(entities_.size()) >= kMaxEntities)
          fail(first, fmt::format("more than {} entities", kMaxEntities));
        const Token t = expect("an entity tag");
        const int tag = to_int32(t, "the entity tag");
        // A point has its coordinates, other entities their bounding box.
        for (int k = 0; k < (dim == 0 ? 3 : 6); ++k)
          to_double(expect_on_line(t.line, "a coordinate"), "a coordinate");
        const std::int64_t n_phys =
            to_count(expect_on_line(t.line, "the number of physical tags"),
                     "the number of physical tags", kMaxTagsPerEntity, "too many");
        std::vector<int> phys;
        for (std::int64_t k = 0; k < n_phys; ++k) {
          const int p = to_int32(expect_on_line(t.line, "a physical tag"), "the physical tag");
          if (std::find(phys.begin(), phys.end(), p) == phys.end()) phys.push_back(p);
        }
        if (dim > 0) {
          const std::int64_t n_bound =
              to_count(expect_on_line(t.line, "the number of bounding entities"),
                       "the number of bounding entities", kMaxTagsPerEntity, "too many");
          for (std::int64_t k = 0; k < n_bound; ++k)
            to_int32(expect_on_line(t.line, "a bounding entity tag"), "the bounding entity tag");
        }
        expect_line_end(t.line, "the entity");
        if (!phys.empty()) any_physical_ = true;
        if (!entities_.emplace(std::pair{dim, tag}, std::move(phys)).second)
          fail(t, fmt::format("entity {} of dimension {} is defined twice", tag, dim));
      }
    }
    seen_entities_ = true;
    expect_section_end("$EndEntities");
  }

  void read_nodes(const Token& header) {
    begin_section(header);
    const Token h = expect("the number of node blocks");
    count_line_ = h.line;
    const std::int64_t room = kMaxGmshNodes - static_cast<std::int64_t>(nodes_.size());
    const std::int64_t n_blocks =
        to_count(h, "the number of node blocks", kMaxGmshNodes, "too many blocks");
    const std::int64_t n_nodes =
        to_count(expect_on_line(h.line, "the number of nodes"), "the number of nodes", room,
                 fmt::format("more than {} nodes are not supported", kMaxGmshNodes));
    to_int(expect_on_line(h.line, "the smallest node tag"), "the smallest node tag");
    to_int(expect_on_line(h.line, "the largest node tag"), "the largest node tag");
    expect_line_end(h.line, "the node counts");

    // Nothing is reserved from the counts: the vectors grow with what the text really holds.
    std::int64_t read = 0;
    for (std::int64_t b = 0; b < n_blocks; ++b) {
      const Token d = expect("a node block (entity dimension)");
      to_dim(d, "the entity dimension");
      to_int32(expect_on_line(d.line, "the entity tag"), "the entity tag");
      const Token par = expect_on_line(d.line, "the parametric flag");
      const std::int64_t parametric = to_int(par, "the parametric flag");
      if (parametric == 1)
        fail(par,
             "parametric node coordinates are not supported; save the mesh without them "
             "(Gmsh: Mesh.SaveParametric = 0)");
      if (parametric != 0)
        fail(par, fmt::format("the parametric flag must be 0 or 1, found {}", parametric));
      const Token nb_tok = expect_on_line(d.line, "the number of nodes in the block");
      const std::int64_t nb =
          to_count(nb_tok, "the number of nodes in the block", n_nodes - read,
                   fmt::format("the blocks hold more nodes than the {} announced on line {}",
                               n_nodes, h.line));
      expect_line_end(d.line, "the node block header");
      const std::size_t first = nodes_.size();
      for (std::int64_t i = 0; i < nb; ++i) {
        const Token t = expect("a node tag");
        const std::int64_t tag = to_int(t, "a node tag");
        if (tag < 1) fail(t, fmt::format("node tags start at 1, found {}", tag));
        expect_line_end(t.line, "the node tag");
        node_tags_.push_back(tag);
        node_lines_.push_back(t.line);
        nodes_.push_back({0.0, 0.0, 0.0});
      }
      for (std::int64_t i = 0; i < nb; ++i) {
        auto& x = nodes_[first + static_cast<std::size_t>(i)];
        const Token t = expect("the x coordinate of a node");
        for (int k = 0; k < 3; ++k) {
          static constexpr const char* kAxis[3] = {"the x coordinate", "the y coordinate",
                                                   "the z coordinate"};
          const Token c = k == 0 ? t : expect_on_line(t.line, kAxis[k]);
          x[k] = to_double(c, kAxis[k]);
          if (!std::isfinite(x[k]))
            fail(c, fmt::format("{} of node {} is not finite ('{}')", kAxis[k],
                                node_tags_[first + static_cast<std::size_t>(i)], shown(c.text)));
        }
        expect_line_end(t.line, "the three coordinates of a node");
      }
      read += nb;
    }
    if (read != n_nodes)
      fail(h, fmt::format("{} nodes are announced here but the blocks hold {}", n_nodes, read));
    seen_nodes_ = true;
    build_node_lookup();
    expect_section_end("$EndNodes");
  }

  // Sorted (tag, index) pairs for finding nodes by tag; finds duplicated tags.
  void build_node_lookup() {
    by_tag_.clear();
    by_tag_.reserve(node_tags_.size());
    for (std::size_t i = 0; i < node_tags_.size(); ++i)
      by_tag_.emplace_back(node_tags_[i], static_cast<std::int64_t>(i));
    std::sort(by_tag_.begin(), by_tag_.end());
    for (std::size_t i = 1; i < by_tag_.size(); ++i)
      if (by_tag_[i].first == by_tag_[i - 1].first) {
        const auto first = static_cast<std::size_t>(by_tag_[i - 1].second);
        const auto again = static_cast<std::size_t>(by_tag_[i].second);
        fail(node_lines_[again], 0,
             fmt::format("node tag {} is defined twice (first on line {})", by_tag_[i].first,
                         node_lines_[first]));
      }
  }

  std::int64_t node_index(const Token& t) const {
    const std::int64_t tag = to_int(t, "a node tag");
    const auto it = std::lower_bound(by_tag_.begin(), by_tag_.end(),
                                     std::pair<std::int64_t, std::int64_t>{tag, INT64_MIN});
    if (it == by_tag_.end() || it->first != tag)
      fail(t, fmt::format("node tag {} is not defined in $Nodes", tag));
    return it->second;
  }

  void read_elements(const Token& header) {
    begin_section(header);
    if (!seen_nodes_)
      fail(header, "$Elements comes before $Nodes: nodes must be defined before the elements");
    if (elements_line_ == 0) elements_line_ = header.line;
    const Token h = expect("the number of element blocks");
    count_line_ = h.line;
    const std::int64_t n_blocks =
        to_count(h, "the number of element blocks", kMaxGmshElements, "too many blocks");
    const std::int64_t n_elements =
        to_count(expect_on_line(h.line, "the number of elements"), "the number of elements",
                 kMaxGmshElements - element_count_,
                 fmt::format("more than {} elements are not supported", kMaxGmshElements));
    to_int(expect_on_line(h.line, "the smallest element tag"), "the smallest element tag");
    to_int(expect_on_line(h.line, "the largest element tag"), "the largest element tag");
    expect_line_end(h.line, "the element counts");

    std::int64_t read = 0;
    for (std::int64_t b = 0; b < n_blocks; ++b) {
      const Token d = expect("an element block (entity dimension)");
      RawBlock raw;
      raw.entity_dim = to_dim(d, "the entity dimension");
      raw.entity_tag = to_int32(expect_on_line(d.line, "the entity tag"), "the entity tag");
      raw.header_line = d.line;
      raw.header_column = d.column;
      const Token type_tok = expect_on_line(d.line, "the element type");
      const std::int64_t code = to_int(type_tok, "the element type");
      raw.type = supported_type(code);
      if (!raw.type) fail(type_tok, unsupported_type_message(code));
      if (raw.type->dim != raw.entity_dim)
        fail(type_tok, fmt::format("element type {} ({}) has dimension {} but its block belongs "
                                   "to an entity of dimension {}",
                                   code, raw.type->name, raw.type->dim, raw.entity_dim));
      const std::int64_t ne =
          to_count(expect_on_line(d.line, "the number of elements in the block"),
                   "the number of elements in the block", n_elements - read,
                   fmt::format("the blocks hold more elements than the {} announced on line {}",
                               n_elements, h.line));
      expect_line_end(d.line, "the element block header");
      const int npe = raw.type->nodes;
      const std::string node_what = fmt::format("a node tag of a {}", raw.type->name);
      const std::string after = fmt::format("the {} node tags of a {}", npe, raw.type->name);
      for (std::int64_t e = 0; e < ne; ++e) {
        const Token t = expect("an element tag");
        if (to_int(t, "an element tag") < 1)
          fail(t, fmt::format("element tags start at 1, found '{}'", shown(t.text)));
        for (int k = 0; k < npe; ++k)
          raw.connectivity.push_back(node_index(expect_on_line(t.line, node_what)));
        expect_line_end(t.line, after);
        raw.lines.push_back(t.line);
      }
      read += ne;
      raw_blocks_.push_back(std::move(raw));
    }
    if (read != n_elements)
      fail(h,
           fmt::format("{} elements are announced here but the blocks hold {}", n_elements, read));
    element_count_ += read;
    expect_section_end("$EndElements");
  }

  // ---- physical groups -----------------------------------------------------------------------

  GmshMesh assemble() {
    section_.clear();
    const int last_line = cur_.line();
    if (!seen_nodes_) fail(last_line, 0, "the file has no $Nodes section");
    if (elements_line_ == 0) fail(last_line, 0, "the file has no $Elements section");
    if (!any_physical_ && !physical_names_.empty()) {
      section_ = "$PhysicalNames";
      fail(physical_names_line_, 0,
           seen_entities_ ? "physical groups are named but no entity in $Entities belongs to one"
                          : "physical groups are named but the file has no $Entities section "
                            "saying which entities belong to them");
    }

    GmshMesh mesh;
    std::map<std::tuple<int, int, int>, std::size_t> block_of;  // (dim, physical tag, type)
    const std::vector<int> unnamed{-1};
    for (RawBlock& raw : raw_blocks_) {
      const std::vector<int>* groups = &unnamed;
      if (any_physical_) {
        const auto it = entities_.find({raw.entity_dim, raw.entity_tag});
        if (it == entities_.end()) {
          section_ = "$Elements";
          fail(raw.header_line, raw.header_column,
               fmt::format("the element block's entity {} of dimension {} is not in $Entities",
                           raw.entity_tag, raw.entity_dim));
        }
        groups = &it->second;  // empty: in no physical group, left out
      }
      for (const int group : *groups) {
        const auto key = std::tuple{raw.entity_dim, group, raw.type->code};
        auto [it, fresh] = block_of.emplace(key, mesh.blocks.size());
        if (fresh) {
          GmshMesh::Block block;
          const auto name = physical_names_.find({raw.entity_dim, group});
          if (name != physical_names_.end()) block.physical_name = name->second;
          block.physical_tag = group;
          block.dim = raw.entity_dim;
          block.gmsh_type = raw.type->code;
          block.nodes_per_element = raw.type->nodes;
          mesh.blocks.push_back(std::move(block));
        }
        GmshMesh::Block& block = mesh.blocks[it->second];
        block.connectivity.insert(block.connectivity.end(), raw.connectivity.begin(),
                                  raw.connectivity.end());
        block.source_lines.insert(block.source_lines.end(), raw.lines.begin(), raw.lines.end());
      }
      raw = RawBlock{};  // frees the memory as we go
    }

    for (const auto& block : mesh.blocks)
      if (!block.source_lines.empty()) mesh.dimension = std::max(mesh.dimension, block.dim);
    if (mesh.dimension < 2) {
      section_ = "$Elements";
      fail(elements_line_, 0,
           any_physical_ ? "no surface or volume element belongs to a physical group: add a "
                           "Physical Surface (2D) or Physical Volume (3D)"
                         : "the mesh has no surface or volume elements");
    }
    mesh.nodes = std::move(nodes_);
    mesh.node_tags = std::move(node_tags_);
    return mesh;
  }

  Cursor cur_;
  std::string source_;
  std::string section_;  // the section being read ("$Nodes"), for messages
  int section_line_ = 0;
  int count_line_ = 0;  // the line with the counts of the section being read

  std::map<std::pair<int, int>, std::string> physical_names_;  // (dim, tag) -> name
  int physical_names_line_ = 0;
  std::map<std::pair<int, int>, std::vector<int>> entities_;  // (dim, tag) -> physical tags
  bool seen_entities_ = false;
  bool any_physical_ = false;

  std::vector<std::array<double, 3>> nodes_;
  std::vector<std::int64_t> node_tags_;
  std::vector<int> node_lines_;
  std::vector<std::pair<std::int64_t, std::int64_t>> by_tag_;  // (tag, index), sorted
  bool seen_nodes_ = false;

  std::vector<RawBlock> raw_blocks_;
  std::int64_t element_count_ = 0;
  int elements_line_ = 0;
};

}  // namespace

GmshMesh parse_gmsh(std::string_view text, const std::string& source_name) {
  if (text.size() > kMaxTextBytes)
    throw InputError(SourceLocation{source_name, 0, 0}, "",
                     fmt::format("the mesh file is {} bytes; at most {} are supported", text.size(),
                                 kMaxTextBytes));
  return Parser(text, source_name).run();
}

GmshMesh read_gmsh(const std::filesystem::path& file) {
  const SourceLocation where{file.string(), 0, 0};
  std::error_code ec;
  // Only a regular file has a size to read up to: a FIFO would block, /dev/zero never end.
  if (const std::string kind = not_a_regular_file(file); !kind.empty())
    throw InputError(where, "", "expected a Gmsh .msh file; '" + file.string() + "' " + kind);
  const std::uintmax_t size = std::filesystem::file_size(file, ec);
  if (ec) throw InputError(where, "", "cannot read the mesh file: " + ec.message());
  if (size > kMaxTextBytes)
    throw InputError(
        where, "",
        fmt::format("the mesh file is {} bytes; at most {} are supported", size, kMaxTextBytes));
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(where, "", "cannot open the mesh file");
  std::string text(static_cast<std::size_t>(size), '\0');
  in.read(text.data(), static_cast<std::streamsize>(size));
  if (static_cast<std::uintmax_t>(in.gcount()) != size)
    throw InputError(where, "", "cannot read the whole mesh file");
  return parse_gmsh(text, file.string());
}

}  // namespace crater::mesh
