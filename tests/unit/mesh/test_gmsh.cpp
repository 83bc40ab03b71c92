// Unit tests of the Gmsh MSH 4.1 reader (src/mesh/gmsh.*): physical groups and element
// blocks of a 2D and a 3D mesh (the 3D one written by Gmsh itself), sparse node tags, files
// without physical groups, and one test per kind of input error, each naming the line.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "mesh/gmsh.hpp"

namespace crater::mesh {
namespace {

// gtest without gmock: whether `message` contains `part`, showing the message if not.
::testing::AssertionResult contains(const std::string& message, const std::string& part) {
  if (message.find(part) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "message: " << message << "\n   lacks: " << part;
}

const std::filesystem::path kMeshDir =
    std::filesystem::path(__FILE__).parent_path().parent_path().parent_path() / "data" / "meshes";

// tests/data/meshes/plate_2x1.msh without its $Comments section; the line numbers in the error
// tests below refer to this text (line 1 = $MeshFormat).
const std::string kPlate = R"($MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
2
1 2 "bottom"
2 1 "plate"
$EndPhysicalNames
$Entities
4 4 1 0
1 0 0 0 0
2 2 0 0 0
3 2 1 0 0
4 0 1 0 0
1 0 0 0 2 0 0 1 2 2 1 -2
2 2 0 0 2 1 0 0 2 2 -3
3 0 1 0 2 1 0 0 2 3 -4
4 0 0 0 0 1 0 0 2 4 -1
1 0 0 0 2 1 0 1 1 4 1 2 3 4
$EndEntities
$Nodes
3 6 1 6
0 1 0 2
1
2
0 0 0
2 0 0
1 1 0 1
3
1 0 0
2 1 0 3
4
5
6
2 1 0
0 1 0
1 1 0
$EndNodes
$Elements
2 4 1 4
1 1 1 2
1 1 3
2 3 2
2 1 3 2
3 1 3 6 5
4 3 2 4 6
$EndElements
)";

std::string replace(std::string text, const std::string& from, const std::string& to) {
  const auto pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  if (pos != std::string::npos) text.replace(pos, from.size(), to);
  return text;
}

std::string replace_all(std::string text, const std::string& from, const std::string& to) {
  for (auto pos = text.find(from); pos != std::string::npos; pos = text.find(from, pos + to.size()))
    text.replace(pos, from.size(), to);
  return text;
}

// The message of the InputError that parsing `text` must throw.
std::string error_of(const std::string& text) {
  try {
    parse_gmsh(text, "t.msh");
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError";
  return "";
}

const GmshMesh::Block* find_block(const GmshMesh& mesh, const std::string& name, int type) {
  for (const auto& b : mesh.blocks)
    if (b.physical_name == name && b.gmsh_type == type) return &b;
  return nullptr;
}

void expect_plate(const GmshMesh& mesh, int line_offset) {
  EXPECT_EQ(mesh.dimension, 2);
  ASSERT_EQ(mesh.nodes.size(), 6u);
  EXPECT_EQ(mesh.node_tags, (std::vector<std::int64_t>{1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(mesh.nodes[1], (std::array<double, 3>{2, 0, 0}));
  EXPECT_EQ(mesh.nodes[5], (std::array<double, 3>{1, 1, 0}));
  ASSERT_EQ(mesh.blocks.size(), 2u);  // in the order they first appear

  const auto& bottom = mesh.blocks[0];
  EXPECT_EQ(bottom.physical_name, "bottom");
  EXPECT_EQ(bottom.physical_tag, 2);
  EXPECT_EQ(bottom.dim, 1);
  EXPECT_EQ(bottom.gmsh_type, 1);
  EXPECT_EQ(bottom.nodes_per_element, 2);
  EXPECT_EQ(bottom.connectivity, (std::vector<std::int64_t>{0, 2, 2, 1}));
  EXPECT_EQ(bottom.source_lines, (std::vector<int>{42 + line_offset, 43 + line_offset}));

  const auto& plate = mesh.blocks[1];
  EXPECT_EQ(plate.physical_name, "plate");
  EXPECT_EQ(plate.physical_tag, 1);
  EXPECT_EQ(plate.dim, 2);
  EXPECT_EQ(plate.gmsh_type, 3);
  EXPECT_EQ(plate.nodes_per_element, 4);
  EXPECT_EQ(plate.element_count(), 2);
  EXPECT_EQ(plate.connectivity, (std::vector<std::int64_t>{0, 2, 5, 4, 2, 1, 3, 5}));
  EXPECT_EQ(plate.source_lines, (std::vector<int>{45 + line_offset, 46 + line_offset}));
}

// ---- meshes that read ---------------------------------------------------------------------

TEST(GmshReader, Plate2DFromFileWithPhysicalSurfaceAndLine) {
  // The file has a 4-line $Comments section after $MeshFormat, which is skipped.
  expect_plate(read_gmsh(kMeshDir / "plate_2x1.msh"), 4);
}

TEST(GmshReader, Plate2DFromTextAndWithWindowsLineEnds) {
  expect_plate(parse_gmsh(kPlate, "t.msh"), 0);
  expect_plate(parse_gmsh(replace_all(kPlate, "\n", "\r\n"), "t.msh"), 0);
  EXPECT_TRUE(
      contains(error_of(replace_all(replace(kPlate, "4 3 2 4 6", "4 3 2 4 60"), "\n", "\r\n")),
               "t.msh:46:9: key '$Elements': node tag 60 is not defined"));
}

TEST(GmshReader, Block3DWrittenByGmsh) {
  // Two hexahedra in the box [0,2]x[0,1]x[0,1], written by Gmsh 4.8.4 (block_2hex_gmsh.geo).
  const GmshMesh mesh = read_gmsh(kMeshDir / "block_2hex_gmsh.msh");
  EXPECT_EQ(mesh.dimension, 3);
  ASSERT_EQ(mesh.nodes.size(), 12u);
  ASSERT_EQ(mesh.blocks.size(), 2u);

  const auto* base = find_block(mesh, "base", 3);
  ASSERT_NE(base, nullptr);
  EXPECT_EQ(base->physical_tag, 2);
  EXPECT_EQ(base->dim, 2);
  EXPECT_EQ(base->element_count(), 2);
  for (const auto n : base->connectivity)
    EXPECT_EQ(mesh.nodes[static_cast<std::size_t>(n)][2], 0.0);

  const auto* block = find_block(mesh, "block", 5);
  ASSERT_NE(block, nullptr);
  EXPECT_EQ(block->physical_tag, 1);
  EXPECT_EQ(block->dim, 3);
  EXPECT_EQ(block->nodes_per_element, 8);
  // Gmsh's node tags 1 9 10 4 5 11 12 8 are nodes 0 8 9 3 4 10 11 7 in file order.
  ASSERT_EQ(block->connectivity.size(), 16u);
  EXPECT_EQ(std::vector<std::int64_t>(block->connectivity.begin(), block->connectivity.begin() + 8),
            (std::vector<std::int64_t>{0, 8, 9, 3, 4, 10, 11, 7}));
  EXPECT_EQ(block->source_lines, (std::vector<int>{86, 87}));
  // Hexahedron order (as VTK's): bottom face, then the top face with node i+4 above node i.
  for (int e = 0; e < 2; ++e)
    for (int i = 0; i < 4; ++i) {
      const auto& lo = mesh.nodes[static_cast<std::size_t>(block->connectivity[8 * e + i])];
      const auto& hi = mesh.nodes[static_cast<std::size_t>(block->connectivity[8 * e + i + 4])];
      EXPECT_NEAR(hi[0], lo[0], 1e-9);
      EXPECT_NEAR(hi[1], lo[1], 1e-9);
      EXPECT_NEAR(hi[2] - lo[2], 1.0, 1e-12);
    }
}

// No $PhysicalNames and no physical tags in $Entities: every element is kept (Gmsh's save-all),
// one unnamed block per element type. Node tags are sparse, unordered and beyond 2^31.
const std::string kNoGroups = R"($MeshFormat
4.1 0 8
$EndMeshFormat
$Entities
0 1 1 0
1 0 0 0 2 0 0 0 0
7 0 0 0 2 1 0 0 0
$EndEntities
$Nodes
2 6 3 5000000000
1 1 0 2
101
3
0 0 0
1 0 0
2 7 0 4
5000000000
40
12
9
2 0 0
1 1 0
0 1 0
2 1 0
$EndNodes
$Elements
2 3 1 3
2 7 3 2
1 101 3 40 12
2 3 5000000000 9 40
1 1 1 1
3 101 3
$EndElements
)";

TEST(GmshReader, NonContiguousNodeTagsAndNoPhysicalGroups) {
  const GmshMesh mesh = parse_gmsh(kNoGroups, "t.msh");
  EXPECT_EQ(mesh.dimension, 2);
  EXPECT_EQ(mesh.node_tags, (std::vector<std::int64_t>{101, 3, 5000000000, 40, 12, 9}));
  EXPECT_EQ(mesh.nodes[3], (std::array<double, 3>{1, 1, 0}));
  ASSERT_EQ(mesh.blocks.size(), 2u);
  EXPECT_EQ(mesh.blocks[0].physical_name, "");
  EXPECT_EQ(mesh.blocks[0].physical_tag, -1);
  EXPECT_EQ(mesh.blocks[0].gmsh_type, 3);
  EXPECT_EQ(mesh.blocks[0].connectivity, (std::vector<std::int64_t>{0, 1, 3, 4, 1, 2, 5, 3}));
  EXPECT_EQ(mesh.blocks[0].source_lines, (std::vector<int>{29, 30}));
  EXPECT_EQ(mesh.blocks[1].physical_tag, -1);
  EXPECT_EQ(mesh.blocks[1].gmsh_type, 1);
  EXPECT_EQ(mesh.blocks[1].connectivity, (std::vector<std::int64_t>{0, 1}));
}

TEST(GmshReader, NoEntitiesSectionAtAll) {
  const std::string text = replace(
      kNoGroups, "$Entities\n0 1 1 0\n1 0 0 0 2 0 0 0 0\n7 0 0 0 2 1 0 0 0\n$EndEntities\n", "");
  const GmshMesh mesh = parse_gmsh(text, "t.msh");
  ASSERT_EQ(mesh.blocks.size(), 2u);
  EXPECT_EQ(mesh.blocks[0].physical_tag, -1);
}

TEST(GmshReader, ElementsOutsidePhysicalGroupsAreLeftOut) {
  // Curve 2 (x = 2) is in no physical group: its line element is not read into any block.
  const std::string text = replace(kPlate, "2 4 1 4\n", "3 5 1 5\n1 2 1 1\n5 2 4\n");
  const GmshMesh mesh = parse_gmsh(text, "t.msh");
  ASSERT_EQ(mesh.blocks.size(), 2u);
  EXPECT_EQ(mesh.blocks[0].physical_name, "bottom");
  EXPECT_EQ(mesh.blocks[0].element_count(), 2);
  EXPECT_EQ(mesh.blocks[1].physical_name, "plate");
}

TEST(GmshReader, ElementInSeveralPhysicalGroupsIsInEachBlock) {
  // Surface 1 is in physical surfaces 1 "plate" and 3 (unnamed); tag 1 is repeated.
  const std::string text =
      replace(kPlate, "1 0 0 0 2 1 0 1 1 4 1 2 3 4", "1 0 0 0 2 1 0 3 1 3 1 4 1 2 3 4");
  const GmshMesh mesh = parse_gmsh(text, "t.msh");
  ASSERT_EQ(mesh.blocks.size(), 3u);
  EXPECT_EQ(mesh.blocks[1].physical_name, "plate");
  EXPECT_EQ(mesh.blocks[2].physical_name, "");
  EXPECT_EQ(mesh.blocks[2].physical_tag, 3);
  EXPECT_EQ(mesh.blocks[2].connectivity, mesh.blocks[1].connectivity);
  EXPECT_EQ(mesh.blocks[2].source_lines, mesh.blocks[1].source_lines);
}

TEST(GmshReader, UnknownSectionsAreSkipped) {
  const std::string text = kPlate +
                           "$NodeData\n1\n\"a view\"\n1\n0.0\n3\n0\n1\n6\n1 0.5\n2 0.5\n3 0.5\n"
                           "4 0.5\n5 0.5\n6 0.5\n$EndNodeData\n"
                           "$Periodic\n0\n$EndPeriodic\n$Comments\n$Nodes is not read here\n"
                           "$EndComments\n";
  expect_plate(parse_gmsh(text, "t.msh"), 0);
}

// ---- errors: each names the file, the line (and column) and the section --------------------

TEST(GmshReaderErrors, FileMissingOrNotAMesh) {
  EXPECT_THROW(read_gmsh(kMeshDir / "no_such_file.msh"), InputError);
  EXPECT_THROW(read_gmsh(kMeshDir), InputError);
  EXPECT_TRUE(contains(error_of(""), "t.msh:1: the file is empty"));
  EXPECT_TRUE(contains(error_of("\n\n$Nodes\n"), "t.msh:3:1: not a Gmsh .msh file"));
}

TEST(GmshReaderErrors, VersionOtherThan41) {
  EXPECT_TRUE(contains(error_of(replace(kPlate, "4.1 0 8", "2.2 0 8")),
                       "t.msh:2:1: key '$MeshFormat': MSH 2.2 is not supported; export MSH 4.1 "
                       "(Gmsh: File > Export, Version 4 ASCII"));
  EXPECT_TRUE(contains(error_of(replace(kPlate, "4.1 0 8", "4 0 8")),
                       "t.msh:2:1: key '$MeshFormat': MSH version 4 is not supported"));
  EXPECT_TRUE(contains(error_of(replace(kPlate, "4.1 0 8", "four 0 8")),
                       "t.msh:2:1: key '$MeshFormat': expected the MSH version (a number)"));
}

TEST(GmshReaderErrors, BinaryFile) {
  EXPECT_TRUE(contains(error_of(replace(kPlate, "4.1 0 8", "4.1 1 8")),
                       "t.msh:2:5: key '$MeshFormat': binary .msh is not supported; save as "
                       "ASCII (Gmsh: Mesh.Binary = 0"));
}

TEST(GmshReaderErrors, TruncatedFile) {
  EXPECT_TRUE(contains(error_of(kPlate.substr(0, kPlate.find("$EndNodes"))),
                       "t.msh:38:1: key '$Nodes': the file ends before $EndNodes: the $Nodes "
                       "section begun on line 21 is not closed"));
  EXPECT_TRUE(contains(error_of(kPlate.substr(0, kPlate.find("4 3 2 4 6"))),
                       "t.msh:46:1: key '$Elements': the file ends inside $Elements (begun on "
                       "line 39) where an element tag was expected: the file is truncated"));
  EXPECT_TRUE(contains(error_of(kPlate.substr(0, kPlate.find("$Nodes"))),
                       "t.msh:21: the file has no $Nodes section"));
  EXPECT_TRUE(contains(error_of(replace(kPlate, "$EndNodes", "$EndNode")),
                       "t.msh:38:1: key '$Nodes': expected $EndNodes to close the $Nodes "
                       "section begun on line 21, found '$EndNode'"));
  EXPECT_TRUE(contains(error_of(kPlate + "$NodeData\n1\n"),
                       "t.msh:48:1: the section $NodeData begun here has no $EndNodeData"));
}

TEST(GmshReaderErrors, NonNumericToken) {
  EXPECT_TRUE(contains(error_of(replace(kPlate, "3 6 1 6", "3 six 1 6")),
                       "t.msh:22:3: key '$Nodes': expected the number of nodes (an integer), "
                       "found 'six'"));
  EXPECT_TRUE(contains(error_of(replace(kPlate, "3 1 3 6 5", "3 1 3 6 5.0")),
                       "t.msh:45:9: key '$Elements': expected a node tag (an integer), found "
                       "'5.0'"));
  EXPECT_TRUE(contains(error_of(replace(kPlate, "2 1 0\n0 1 0", "2 1 0\n0 y 0")),
                       "t.msh:36:3: key '$Nodes': expected the y coordinate (a number)"));
}

TEST(GmshReaderErrors, CountsThatDoNotMatch) {
  EXPECT_TRUE(contains(error_of(replace(kPlate, "3 6 1 6", "3 7 1 7")),
                       "t.msh:22:1: key '$Nodes': 7 nodes are announced here but the blocks "
                       "hold 6"));
  EXPECT_TRUE(contains(error_of(replace(kPlate, "2 1 3 2", "2 1 3 3")),
                       "t.msh:44:7: key '$Elements': the number of elements in the block is 3: "
                       "the blocks hold more elements than the 4 announced on line 40"));
  EXPECT_TRUE(
      contains(error_of(replace(replace(kPlate, "2 4 1 4", "2 5 1 5"), "2 1 3 2", "2 1 3 3")),
               "t.msh:47:1: key '$Elements': expected an element tag (an integer), found "
               "'$EndElements': the section ends before the entries announced on line "
               "40"));
  EXPECT_TRUE(
      contains(error_of(replace(replace(kPlate, "2 4 1 4", "2 3 1 4"), "2 1 3 2", "2 1 3 1")),
               "t.msh:46:1: key '$Elements': expected $EndElements, found '4': the "
               "section holds more entries than announced on line 40"));
  EXPECT_TRUE(contains(error_of(replace(kPlate, "2\n1 2 \"bottom\"", "3\n1 2 \"bottom\"")),
                       "t.msh:8:1: key '$PhysicalNames': expected the dimension of a physical "
                       "group (an integer), found '$EndPhysicalNames'"));
}

TEST(GmshReaderErrors, WrongNumberOfNodesInAnElement) {
  EXPECT_TRUE(contains(error_of(replace(kPlate, "3 1 3 6 5", "3 1 3 6")),
                       "t.msh:45: key '$Elements': the line ends where a node tag of a 4-node "
                       "quadrangle was expected"));
  EXPECT_TRUE(contains(error_of(replace(kPlate, "3 1 3 6 5", "3 1 3 6 5 2")),
                       "t.msh:45:11: key '$Elements': unexpected '2' after the 4 node tags of a "
                       "4-node quadrangle"));
}

TEST(GmshReaderErrors, NegativeOrAbsurdCounts) {
  EXPECT_TRUE(contains(error_of(replace(kPlate, "3 6 1 6", "3 -6 1 6")),
                       "t.msh:22:3: key '$Nodes': the number of nodes must not be negative"));
  EXPECT_TRUE(contains(error_of(replace(kPlate, "3 6 1 6", "3 999999999999 1 6")),
                       "t.msh:22:3: key '$Nodes': the number of nodes is 999999999999: more "
                       "than 50000000 nodes are not supported"));
  EXPECT_TRUE(contains(error_of(replace(kPlate, "3 6 1 6", "3 99999999999999999999 1 6")),
                       "t.msh:22:3: key '$Nodes': the number of nodes '99999999999999999999' "
                       "is out of range"));
  // A huge block count with few blocks behind it ends at the end of the section, quickly.
  EXPECT_TRUE(contains(error_of(replace(kPlate, "3 6 1 6", "40000000 6 1 6")),
                       "t.msh:38:1: key '$Nodes': expected the entity dimension (an integer), "
                       "found '$EndNodes': the section ends before the entries announced on line "
                       "22"));
  EXPECT_TRUE(contains(error_of(replace(kPlate, "4 4 1 0", "4 4 1 4000000000")),
                       "t.msh:10:7: key '$Entities': the number of volumes is 4000000000: too "
                       "many entities"));
  EXPECT_TRUE(contains(error_of(replace(kPlate, "1 0 0 0 2 1 0 1 1 4", "1 0 0 0 2 1 0 99999 1 4")),
                       "t.msh:19: key '$Entities': the line ends where a physical tag was "
                       "expected"));
}

TEST(GmshReaderErrors, UndefinedNodeTag) {
  EXPECT_TRUE(contains(error_of(replace(kPlate, "4 3 2 4 6", "4 3 2 4 60")),
                       "t.msh:46:9: key '$Elements': node tag 60 is not defined in $Nodes"));
  const std::string reversed =
      "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Elements\n0 0 0 0\n"
      "$EndElements\n";
  EXPECT_TRUE(contains(error_of(reversed),
                       "t.msh:4:1: key '$Elements': $Elements comes before "
                       "$Nodes"));
}

TEST(GmshReaderErrors, DuplicateNodeTag) {
  EXPECT_TRUE(contains(error_of(replace(kPlate, "1 1 0 1\n3\n", "1 1 0 1\n2\n")),
                       "t.msh:29: key '$Nodes': node tag 2 is defined twice (first on line 25)"));
}

TEST(GmshReaderErrors, NonFiniteCoordinate) {
  const std::string end = "0 1 0\n1 1 0\n$EndNodes";
  EXPECT_TRUE(contains(error_of(replace(kPlate, end, "0 1 0\n1 nan 0\n$EndNodes")),
                       "t.msh:37:3: key '$Nodes': the y coordinate of node 6 is not finite"));
  EXPECT_TRUE(contains(error_of(replace(kPlate, end, "0 1 0\n1 1 -inf\n$EndNodes")),
                       "t.msh:37:5: key '$Nodes': the z coordinate of node 6 is not finite"));
  EXPECT_TRUE(contains(error_of(replace(kPlate, end, "0 1 0\n1e999 1 0\n$EndNodes")),
                       "t.msh:37:1: key '$Nodes': the x coordinate '1e999' is not a finite "
                       "number"));
}

TEST(GmshReaderErrors, PhysicalNameTooLongOrUnquoted) {
  EXPECT_TRUE(contains(error_of(replace(kPlate, "\"plate\"", "\"" + std::string(128, 'p') + "\"")),
                       "t.msh:7:5: key '$PhysicalNames': the physical name is 128 characters "
                       "long; at most 127 are allowed"));
  EXPECT_NO_THROW(
      parse_gmsh(replace(kPlate, "\"plate\"", "\"" + std::string(127, 'p') + "\""), "t.msh"));
  EXPECT_TRUE(contains(error_of(replace(kPlate, "\"plate\"", "\"plate")),
                       "t.msh:7:5: key '$PhysicalNames': unterminated quotes"));
  EXPECT_TRUE(contains(error_of(replace(kPlate, "\"plate\"", "plate")),
                       "t.msh:7:5: key '$PhysicalNames': expected the physical name in double "
                       "quotes"));
  EXPECT_TRUE(contains(error_of(replace(kPlate, "\"plate\"", "\"plate\" x")),
                       "t.msh:7:13: key '$PhysicalNames': unexpected 'x' after the physical "
                       "name"));
}

TEST(GmshReaderErrors, UnsupportedElementType) {
  const std::string text =
      replace(kPlate, "2 1 3 2\n3 1 3 6 5\n4 3 2 4 6", "2 1 9 1\n3 1 3 6 5 2 4");
  EXPECT_TRUE(contains(error_of(text),
                       "t.msh:44:5: key '$Elements': element type 9 (6-node second-order "
                       "triangle) is not supported: use first-order elements "
                       "(Mesh.ElementOrder = 1)"));
  EXPECT_TRUE(contains(error_of(replace(kPlate, "2 1 3 2", "2 1 6 2")),
                       "t.msh:44:5: key '$Elements': element type 6 (6-node prism)"));
  EXPECT_TRUE(contains(error_of(replace(kPlate, "2 1 3 2", "1 1 3 2")),
                       "t.msh:44:5: key '$Elements': element type 3 (4-node quadrangle) has "
                       "dimension 2 but its block belongs to an entity of dimension 1"));
}

TEST(GmshReaderErrors, ParametricNodesAndPartitionedMeshes) {
  EXPECT_TRUE(contains(error_of(replace(kPlate, "\n0 1 0 2\n", "\n0 1 1 2\n")),
                       "t.msh:23:5: key '$Nodes': parametric node coordinates are not "
                       "supported"));
  EXPECT_TRUE(contains(error_of(replace(kPlate, "$Nodes\n", "$PartitionedEntities\n$Nodes\n")),
                       "t.msh:21:1: partitioned meshes are not supported"));
}

TEST(GmshReaderErrors, PhysicalGroupsThatDoNotFit) {
  EXPECT_TRUE(contains(error_of(replace(kPlate, "2 1 3 2", "2 5 3 2")),
                       "t.msh:44:1: key '$Elements': the element block's entity 5 of dimension "
                       "2 is not in $Entities"));
  // Only the bottom line is in a physical group: nothing for a 2D part.
  EXPECT_TRUE(contains(error_of(replace(kPlate, "1 0 0 0 2 1 0 1 1 4", "1 0 0 0 2 1 0 0 4")),
                       "t.msh:39: key '$Elements': no surface or volume element belongs to a "
                       "physical group"));
  // Names but no $Entities to say which elements they hold.
  const auto from = kPlate.find("$Entities"), to = kPlate.find("$Nodes");
  EXPECT_TRUE(contains(error_of(kPlate.substr(0, from) + kPlate.substr(to)),
                       "t.msh:4: key '$PhysicalNames': physical groups are named but the file "
                       "has no $Entities section"));
  EXPECT_TRUE(contains(error_of(replace(kPlate, "2 1 \"plate\"", "1 2 \"plate\"")),
                       "t.msh:7:1: key '$PhysicalNames': physical group 2 of dimension 1 is "
                       "named twice"));
}

// Hostile input: every prefix and many one-byte changes of valid files either read or give an
// InputError (run under the sanitizer preset, this also checks for memory errors).
TEST(GmshReaderErrors, EveryPrefixAndByteChangeFailsCleanly) {
  std::vector<std::string> texts{kPlate, kNoGroups};
  for (const auto& text : texts) {
    for (std::size_t n = 0; n < text.size(); ++n) {
      try {
        parse_gmsh(std::string_view(text).substr(0, n), "t.msh");
      } catch (const InputError&) {
      }
    }
    for (std::size_t i = 0; i < text.size(); ++i)
      for (const char c : std::string("$-9 \n\"x.e0\t\r")) {
        std::string changed = text;
        changed[i] = c;
        try {
          parse_gmsh(changed, "t.msh");
        } catch (const InputError&) {
        }
      }
  }
}

}  // namespace
}  // namespace crater::mesh
