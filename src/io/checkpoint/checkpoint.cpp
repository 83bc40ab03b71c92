#include "io/checkpoint/checkpoint.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iterator>

#include "core/hash.hpp"
#include "io/output/atomic_file.hpp"

namespace crater::io {

namespace {
constexpr const char* kMagic = "crater checkpoint v1";
}

void write_checkpoint(const std::filesystem::path& path, const CheckpointHeader& h,
                      const std::string& payload) {
  const std::string line =
      fmt::format("{} dim={} scenario={} step={} time={:a} bytes={} checksum={:016x}\n", kMagic,
                  h.dimension, h.scenario_hash, h.step, h.time_s, payload.size(), fnv1a(payload));
  write_file_atomic(path, line + payload);
}

CheckpointHeader read_checkpoint(const std::filesystem::path& path, std::string& payload) {
  auto refuse = [&](const std::string& why) {
    throw InputError({path.string(), 0, 0}, "checkpoint", "a checkpoint crater can use; " + why);
  };
  std::ifstream in(path, std::ios::binary);
  if (!in) refuse("the file cannot be opened");
  std::string line;
  if (!std::getline(in, line) || line.size() > 512) refuse("no checkpoint header");
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
               ? "its format version is not v1 or its header is damaged"
               : "not a crater checkpoint (no header line)");
  h.scenario_hash = hash;
  h.step = step;
  char* end = nullptr;
  h.time_s = std::strtod(time_text, &end);
  if (end == time_text || *end != '\0') refuse("its header is damaged (time)");
  payload.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  if (payload.size() != bytes)
    refuse(fmt::format("it holds {} bytes of state, its header says {} (truncated or damaged)",
                       payload.size(), bytes));
  if (fnv1a(payload) != sum) refuse("its checksum does not match (the file is damaged)");
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
  for (auto it = files.rbegin(); it != files.rend(); ++it) {
    std::string payload;
    try {
      read_checkpoint(*it, payload);
      return *it;
    } catch (const InputError& e) {
      spdlog::warn("skipping {}: {}", it->string(), e.what());
    }
  }
  throw InputError({run_dir.string(), 0, 0}, "--resume",
                   "a run directory with a usable checkpoint in checkpoints/ (none found; set "
                   "[output] checkpoint_every_steps or checkpoint_every_s)");
}

}  // namespace crater::io
