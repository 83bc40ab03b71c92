// Reader for Gmsh meshes in the MSH 4.1 ASCII format (Gmsh reference manual, section "MSH file
// format", version 4.1). It gives the nodes and, per physical group, the elements of each type;
// it turns no element around and checks no geometry (inverted elements are the caller's
// business).
//
// Read: $MeshFormat (4.1, ASCII only), $PhysicalNames, $Entities (which physical groups each
// geometric entity belongs to), $Nodes (non-parametric) and $Elements of the types
//    1  2-node line          2  3-node triangle      3  4-node quadrangle
//    4  4-node tetrahedron   5  8-node hexahedron   15  1-node point
// Any other element type, binary files, MSH 2.x/4.0, parametric nodes and partitioned meshes
// ($PartitionedEntities) are refused with an InputError. Sections it does not know ($Comments,
// $Periodic, $NodeData, ...) are skipped up to their $End line.
//
// Node order inside an element is Gmsh's, which for the linear types is also VTK's:
//   quadrangle: 0-1-2-3 counter-clockwise around the face normal;
//   hexahedron: 0-1-2-3 the bottom face (counter-clockwise seen from the top, i.e. from the
//               side of 4-7), then 4-5-6-7 the top face, node 4 above node 0 and so on.
//
// Physical groups: an element belongs to every physical group of its entity (an entity can be
// in several, of the entity's dimension). If the file has no physical group at all, every
// element is kept in unnamed blocks (physical_tag -1, like Gmsh's Mesh.SaveAll); otherwise
// elements of entities in no physical group are left out, as Gmsh does when it saves.
//
// Input is treated as untrusted: counts are checked against what follows, nothing is reserved
// from a count before the text can hold it, and the totals are capped (kMaxGmshNodes,
// kMaxGmshElements). Every error names the file, line and column.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace crater::mesh {

/// Largest node and element counts accepted (each), far above what one explicit FE part needs.
inline constexpr std::int64_t kMaxGmshNodes = 50'000'000;
inline constexpr std::int64_t kMaxGmshElements = 50'000'000;

struct GmshMesh {
  /// Highest dimension of the elements kept: 2 or 3 (a mesh with neither is an InputError).
  int dimension = 0;
  /// All nodes of the file, numbered 0.. in the order their tags appear in $Nodes, including
  /// nodes no kept element uses. Coordinates in the file's unit (x, y, z; z = 0 for flat meshes).
  std::vector<std::array<double, 3>> nodes;
  /// The Gmsh tag of each node above (tags may be sparse and unordered).
  std::vector<std::int64_t> node_tags;

  /// The elements of one element type in one physical group, in file order.
  struct Block {
    std::string physical_name;  ///< from $PhysicalNames; "" if the group has no name
    int physical_tag = -1;      ///< -1 when the file has no physical groups
    int dim = 0;                ///< dimension of the group and of its elements (0..3)
    int gmsh_type = 0;          ///< 1, 2, 3, 4, 5 or 15 (see above)
    /// 0-based indices into `nodes`, nodes_per_element per element, in Gmsh's node order.
    std::vector<std::int64_t> connectivity;
    int nodes_per_element = 0;
    /// The line of the file each element is on, for later error messages.
    std::vector<int> source_lines;

    std::int64_t element_count() const {
      return nodes_per_element > 0
                 ? static_cast<std::int64_t>(connectivity.size()) / nodes_per_element
                 : 0;
    }
  };
  /// One block per (physical group, element type), in the order they first appear in the file.
  std::vector<Block> blocks;
};

/// Reads a .msh file; throws InputError (file, line, column) if it cannot be read or is not a
/// valid MSH 4.1 ASCII mesh of the supported element types.
GmshMesh read_gmsh(const std::filesystem::path& file);

/// Parses the text of a .msh file; `source_name` is the file name used in error messages.
GmshMesh parse_gmsh(std::string_view text, const std::string& source_name);

}  // namespace crater::mesh
