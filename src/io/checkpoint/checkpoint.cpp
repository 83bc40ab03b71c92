#include "io/checkpoint/checkpoint.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iterator>

#include "core/file_kind.hpp"
#include "core/hash.hpp"
#include "io/output/atomic_file.hpp"

namespace crater::io {

namespace {
constexpr const char* kMagic = "crater checkpoint v3";
}

namespace {
std::string header_line(const CheckpointHeader& h, std::uint64_t bytes, std::uint64_t checksum) {
  return fmt::format("{} dim={} scenario={} step={} time={:a} bytes={:020d} checksum={:016x}\n",
                     kMagic, h.dimension, h.scenario_hash, h.step, h.time_s, bytes, checksum);
}
}  // namespace

CheckpointFile::CheckpointFile(const std::filesystem::path& path, const CheckpointHeader& header)
    : file_(std::make_unique<AtomicFile>(path)),
      header_(header),
      writer_([this](std::string_view bytes) { file_->write(bytes); }) {
  file_->write(header_line(header_, 0, 0));  // the same length as the final line
}

CheckpointFile::~CheckpointFile() = default;

void CheckpointFile::commit() {
  writer_.flush();
  file_->write_at(0, header_line(header_, writer_.size(), writer_.checksum()));
  file_->commit();
}

CheckpointHeader read_checkpoint(const std::filesystem::path& path, std::string& payload) {
  auto refuse = [&](const std::string& why) {
    throw InputError({path.string(), 0, 0}, "checkpoint", "a checkpoint crater can use; " + why);
  };
  // Nothing is read from a FIFO or a device, and nothing the size of the payload is allocated
  // before the file's size and checksum agree with its header: a hostile file is refused
  // with the memory of a small buffer.
  if (const std::string kind = not_a_regular_file(path); !kind.empty()) refuse("it " + kind);
  std::ifstream in(path, std::ios::binary);
  if (!in) refuse("the file cannot be opened");
  std::string line;
  for (char ch; line.size() <= 512 && in.get(ch) && ch != '\n';)
    line.push_back(ch);
  if (!in || line.size() > 512) refuse("not a crater checkpoint (no header line)");
  CheckpointHeader h;
  char hash[64] = {0};
  long long step = 0;
  unsigned long long bytes = 0, sum = 0;
  char time_text[64] = {0};
  const std::string fmt_text =
      std::string(kMagic) + " dim=%d scenario=%63s step=%lld time=%63s bytes=%llu checksum=%16llx";
  if (std::sscanf(line.c_str(), fmt_text.c_str(), &h.dimension, hash, &step, time_text, &bytes,
                  &sum) != 6)
    refuse(line.rfind("crater checkpoint", 0) == 0
               ? "its format version is not v3 or its header is damaged"
               : "not a crater checkpoint (no header line)");
  h.scenario_hash = hash;
  h.step = step;
  char* end = nullptr;
  h.time_s = std::strtod(time_text, &end);
  if (end == time_text || *end != '\0') refuse("its header is damaged (time)");
  std::error_code ec;
  const std::uintmax_t file_bytes = std::filesystem::file_size(path, ec);
  const std::uintmax_t held =
      ec ? 0 : file_bytes - std::min<std::uintmax_t>(file_bytes, line.size() + 1);
  if (ec || held != bytes)
    refuse(fmt::format("it holds {} bytes of state, its header says {} (truncated or damaged)",
                       held, bytes));
  std::uint64_t running = fnv1a({});
  std::vector<char> chunk(1 << 20);
  const auto start = in.tellg();
  for (std::uintmax_t left = held; left > 0;) {
    const auto n = static_cast<std::streamsize>(std::min<std::uintmax_t>(left, chunk.size()));
    if (!in.read(chunk.data(), n)) refuse("it could not be read to its end");
    running = fnv1a({chunk.data(), static_cast<std::size_t>(n)}, running);
    left -= static_cast<std::uintmax_t>(n);
  }
  if (running != sum) refuse("its checksum does not match (the file is damaged)");
  in.clear();
  in.seekg(start);
  payload.resize(static_cast<std::size_t>(held));
  if (held > 0 && !in.read(payload.data(), static_cast<std::streamsize>(held)))
    refuse("it could not be read to its end");
  return h;
}

std::filesystem::path newest_checkpoint(const std::filesystem::path& run_dir) {
  const auto dir = run_dir / "checkpoints";
  std::vector<std::filesystem::path> files;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec))
    if (e.path().extension() == ".ckpt") files.push_back(e.path());
  // Names carry the zero-padded step: the newest sorts last.
  std::sort(files.begin(), files.end());
  std::string skipped;
  for (auto it = files.rbegin(); it != files.rend(); ++it) {
    std::string payload;
    try {
      read_checkpoint(*it, payload);
      return *it;
    } catch (const InputError& e) {
      spdlog::warn("skipping {}: {}", it->string(), e.what());
      if (skipped.size() < 2000) skipped += std::string("\n  ") + e.what();
    }
  }
  throw InputError({run_dir.string(), 0, 0}, "--resume",
                   files.empty() ? "a run directory with a usable checkpoint in checkpoints/ (none "
                                   "found; set [output] checkpoint_every_steps or "
                                   "checkpoint_every_s)"
                                 : "a run directory with a usable checkpoint in checkpoints/; "
                                   "none of its checkpoints can be used:" +
                                       skipped);
}

}  // namespace crater::io
