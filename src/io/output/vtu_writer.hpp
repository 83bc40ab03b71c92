// VTK XML UnstructuredGrid (.vtu) and ParaView collection (.pvd) writers.
// Format: VTK file format 1.0, little endian, UInt64 block headers, uncompressed, data either
// raw-appended or inline base64 (both read by ParaView and vtkXMLUnstructuredGridReader).
// 2D points and vectors are padded to 3 components with z = 0, as ParaView expects.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "core/types.hpp"

namespace crater::io {

/// One data array to write. Exactly one of real/integer is set; `components` are stored per
/// entity in the source, `pad_to_3` widens 2-component vectors for ParaView.
struct VtuArray {
  std::string name;
  int components = 1;
  const Real* real = nullptr;
  const std::int64_t* integer = nullptr;
  bool pad_to_3 = false;
};

struct VtuMesh {
  Index num_points = 0;
  int dimension = 3;
  const Real* points = nullptr;  // num_points x dimension
  // Cells; when empty, every point becomes a VTK_VERTEX cell.
  const std::vector<std::int64_t>* connectivity = nullptr;
  const std::vector<std::int64_t>* offsets = nullptr;
  const std::vector<std::uint8_t>* cell_types = nullptr;
};

enum class VtuFormat { Appended, Base64 };

/// Writes one .vtu file atomically. `time_s` is stored as the TimeValue field.
void write_vtu(const std::filesystem::path& path, Real time_s, const VtuMesh& mesh,
               const std::vector<VtuArray>& point_arrays, const std::vector<VtuArray>& cell_arrays,
               VtuFormat format);

/// Writes one ParaView parallel file (.pvtu) atomically over `pieces` (.vtu paths relative to
/// it, one per MPI rank, each written by write_vtu with arrays of the names, kinds and
/// components of `point_arrays` and `cell_arrays`; their data are not read here).
void write_pvtu(const std::filesystem::path& path, const std::vector<VtuArray>& point_arrays,
                const std::vector<VtuArray>& cell_arrays, const std::vector<std::string>& pieces);

/// A ParaView collection: one entry per output time, rewritten (atomically) after each frame.
class PvdCollection {
 public:
  explicit PvdCollection(std::filesystem::path path) : path_(std::move(path)) {}
  void add(Real time_s, const std::string& relative_file);
  /// The frames so far, and setting them back (a resumed run: the next add() rewrites all).
  const std::vector<std::pair<Real, std::string>>& entries() const { return entries_; }
  void restore(std::vector<std::pair<Real, std::string>> e) { entries_ = std::move(e); }

 private:
  std::filesystem::path path_;
  std::vector<std::pair<Real, std::string>> entries_;
};

}  // namespace crater::io
