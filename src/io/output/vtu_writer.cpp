#include "io/output/vtu_writer.hpp"

#include <fmt/format.h>
#include <cstring>

#include "io/output/atomic_file.hpp"

namespace crater::io {
namespace {

constexpr std::uint8_t kVtkVertex = 1;

// A data block: raw bytes to be written with a UInt64 length header.
struct Block {
  std::string bytes;
};

void append_raw(std::string& out, const void* p, std::size_t n) {
  out.append(static_cast<const char*>(p), n);
}

template <class T>
Block make_block(const T* data, Index count, int components_in, bool pad_to_3) {
  Block b;
  const int comps_out = pad_to_3 ? 3 : components_in;
  b.bytes.reserve(static_cast<std::size_t>(count) * comps_out * sizeof(T));
  if (!pad_to_3 || components_in == 3) {
    append_raw(b.bytes, data, static_cast<std::size_t>(count) * components_in * sizeof(T));
    return b;
  }
  const T zero{};
  for (Index i = 0; i < count; ++i) {
    append_raw(b.bytes, data + i * components_in, components_in * sizeof(T));
    for (int c = components_in; c < 3; ++c)
      append_raw(b.bytes, &zero, sizeof(T));
  }
  return b;
}

std::string base64(const std::string& in) {
  static const char* tbl = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((in.size() + 2) / 3 * 4);
  std::size_t i = 0;
  const auto* s = reinterpret_cast<const unsigned char*>(in.data());
  for (; i + 2 < in.size(); i += 3) {
    const unsigned v = (s[i] << 16) | (s[i + 1] << 8) | s[i + 2];
    out += tbl[(v >> 18) & 63];
    out += tbl[(v >> 12) & 63];
    out += tbl[(v >> 6) & 63];
    out += tbl[v & 63];
  }
  if (i < in.size()) {
    unsigned v = s[i] << 16;
    if (i + 1 < in.size()) v |= s[i + 1] << 8;
    out += tbl[(v >> 18) & 63];
    out += tbl[(v >> 12) & 63];
    out += (i + 1 < in.size()) ? tbl[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::string xml_escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '<':
        o += "&lt;";
        break;
      case '>':
        o += "&gt;";
        break;
      case '&':
        o += "&amp;";
        break;
      case '"':
        o += "&quot;";
        break;
      default:
        o += c;
    }
  }
  return o;
}

class VtuBuilder {
 public:
  explicit VtuBuilder(VtuFormat f) : format_(f) {}

  // Emits the DataArray element for `b` and stores its payload.
  // `tuples` > 0 writes NumberOfTuples, which FieldData arrays need (no point/cell count).
  void array(std::string& xml, const char* type, const std::string& name, int comps, Block b,
             Index tuples = 0) {
    const std::uint64_t n = b.bytes.size();
    std::string payload;
    append_raw(payload, &n, sizeof n);
    payload += b.bytes;
    std::string name_attr = name.empty() ? "" : " Name=\"" + xml_escape(name) + "\"";
    if (tuples > 0) name_attr += fmt::format(" NumberOfTuples=\"{}\"", tuples);
    if (format_ == VtuFormat::Appended) {
      xml += fmt::format(
          "        <DataArray type=\"{}\"{} NumberOfComponents=\"{}\" format=\"appended\" "
          "offset=\"{}\"/>\n",
          type, name_attr, comps, appended_.size());
      appended_ += payload;
    } else {
      xml += fmt::format(
          "        <DataArray type=\"{}\"{} NumberOfComponents=\"{}\" format=\"binary\">\n", type,
          name_attr, comps);
      xml += "          " + base64(payload) + "\n        </DataArray>\n";
    }
  }

  std::string finish(std::string xml) {
    if (format_ == VtuFormat::Appended) {
      xml += "  <AppendedData encoding=\"raw\">\n   _";
      xml += appended_;
      xml += "\n  </AppendedData>\n";
    }
    xml += "</VTKFile>\n";
    return xml;
  }

 private:
  VtuFormat format_;
  std::string appended_;
};

void data_arrays(std::string& xml, VtuBuilder& vb, const std::vector<VtuArray>& arrays,
                 Index count) {
  for (const auto& a : arrays) {
    const int comps = a.pad_to_3 ? 3 : a.components;
    if (a.integer)
      vb.array(xml, "Int64", a.name, comps, make_block(a.integer, count, a.components, a.pad_to_3));
    else
      vb.array(xml, "Float64", a.name, comps, make_block(a.real, count, a.components, a.pad_to_3));
  }
}

}  // namespace

void write_vtu(const std::filesystem::path& path, Real time_s, const VtuMesh& mesh,
               const std::vector<VtuArray>& point_arrays, const std::vector<VtuArray>& cell_arrays,
               VtuFormat format) {
  const bool vertices = mesh.connectivity == nullptr || mesh.connectivity->empty();
  const Index num_cells = vertices ? mesh.num_points : static_cast<Index>(mesh.cell_types->size());

  VtuBuilder vb(format);
  std::string xml =
      "<?xml version=\"1.0\"?>\n"
      "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
      "header_type=\"UInt64\">\n"
      "  <UnstructuredGrid>\n"
      "    <FieldData>\n";
  vb.array(xml, "Float64", "TimeValue", 1, make_block(&time_s, 1, 1, false), 1);
  xml += "    </FieldData>\n";
  xml += fmt::format("    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n", mesh.num_points,
                     num_cells);
  xml += "      <PointData>\n";
  data_arrays(xml, vb, point_arrays, mesh.num_points);
  xml += "      </PointData>\n      <CellData>\n";
  data_arrays(xml, vb, cell_arrays, num_cells);
  xml += "      </CellData>\n      <Points>\n";
  vb.array(xml, "Float64", "Points", 3,
           make_block(mesh.points, mesh.num_points, mesh.dimension, mesh.dimension != 3));
  xml += "      </Points>\n      <Cells>\n";
  if (vertices) {
    std::vector<std::int64_t> conn(static_cast<std::size_t>(mesh.num_points));
    std::vector<std::int64_t> offs(static_cast<std::size_t>(mesh.num_points));
    for (Index i = 0; i < mesh.num_points; ++i) {
      conn[static_cast<std::size_t>(i)] = i;
      offs[static_cast<std::size_t>(i)] = i + 1;
    }
    const std::vector<std::uint8_t> types(static_cast<std::size_t>(mesh.num_points), kVtkVertex);
    vb.array(xml, "Int64", "connectivity", 1, make_block(conn.data(), mesh.num_points, 1, false));
    vb.array(xml, "Int64", "offsets", 1, make_block(offs.data(), mesh.num_points, 1, false));
    vb.array(xml, "UInt8", "types", 1, make_block(types.data(), mesh.num_points, 1, false));
  } else {
    vb.array(xml, "Int64", "connectivity", 1,
             make_block(mesh.connectivity->data(), static_cast<Index>(mesh.connectivity->size()), 1,
                        false));
    vb.array(xml, "Int64", "offsets", 1,
             make_block(mesh.offsets->data(), static_cast<Index>(mesh.offsets->size()), 1, false));
    vb.array(
        xml, "UInt8", "types", 1,
        make_block(mesh.cell_types->data(), static_cast<Index>(mesh.cell_types->size()), 1, false));
  }
  xml += "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n";
  write_file_atomic(path, vb.finish(std::move(xml)));
}

void write_pvtu(const std::filesystem::path& path, const std::vector<VtuArray>& point_arrays,
                const std::vector<VtuArray>& cell_arrays, const std::vector<std::string>& pieces) {
  auto declare = [](std::string& xml, const std::vector<VtuArray>& arrays) {
    for (const auto& a : arrays)
      xml += fmt::format("      <PDataArray type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\"/>\n",
                         a.integer ? "Int64" : "Float64", xml_escape(a.name),
                         a.pad_to_3 ? 3 : a.components);
  };
  std::string xml =
      "<?xml version=\"1.0\"?>\n"
      "<VTKFile type=\"PUnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
      "header_type=\"UInt64\">\n"
      "  <PUnstructuredGrid GhostLevel=\"0\">\n"
      "    <PPointData>\n";
  declare(xml, point_arrays);
  xml += "    </PPointData>\n    <PCellData>\n";
  declare(xml, cell_arrays);
  xml +=
      "    </PCellData>\n    <PPoints>\n"
      "      <PDataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\"/>\n"
      "    </PPoints>\n";
  for (const auto& piece : pieces)
    xml += fmt::format("    <Piece Source=\"{}\"/>\n", xml_escape(piece));
  xml += "  </PUnstructuredGrid>\n</VTKFile>\n";
  write_file_atomic(path, xml);
}

void PvdCollection::add(Real time_s, const std::string& relative_file) {
  entries_.emplace_back(time_s, relative_file);
  std::string xml =
      "<?xml version=\"1.0\"?>\n"
      "<VTKFile type=\"Collection\" version=\"1.0\" byte_order=\"LittleEndian\">\n"
      "  <Collection>\n";
  for (const auto& [t, f] : entries_)
    xml += fmt::format("    <DataSet timestep=\"{:.17g}\" part=\"0\" file=\"{}\"/>\n", t,
                       xml_escape(f));
  xml += "  </Collection>\n</VTKFile>\n";
  write_file_atomic(path_, xml);
}

}  // namespace crater::io
