// crater report, sweep and verify: write the embedded script (report, sweep, verify) to a temporary
// file and run it with the system Python, passing the arguments on as an argv array (no shell,
// no quoting).
#include "app/report.hpp"

#include <fmt/format.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "app/report_script.hpp"
#include "app/sweep_script.hpp"
#include "app/verify_script.hpp"
#include "io/scenario/load.hpp"

namespace crater::app {

namespace {

constexpr const char* kDebianPackages = "python3-vtk9 python3-matplotlib python3-numpy";
constexpr int kExitInput = 2;
constexpr int kExitOther = 1;

// The interpreter: the environment's CRATER_PYTHON, else CMake's (Debian's /usr/bin/python3,
// the one python3-vtk9 and the other Debian modules load in).
std::string python_path() {
  const char* env = std::getenv("CRATER_PYTHON");
  return env != nullptr && *env != '\0' ? std::string(env) : std::string(CRATER_PYTHON);
}

// The script in a fresh file of the temporary directory, removed again on destruction.
class TemporaryScript {
 public:
  explicit TemporaryScript(std::string_view text) {
    const char* tmp = std::getenv("TMPDIR");
    path_ = std::string(tmp != nullptr && *tmp != '\0' ? tmp : "/tmp") + "/crater-script-XXXXXX.py";
    const int fd = mkstemps(path_.data(), 3);  // 3: the ".py" after the Xs
    if (fd < 0) {
      const std::string msg = std::strerror(errno);
      path_.clear();
      throw std::runtime_error(fmt::format("cannot create a temporary file: {}", msg));
    }
    std::size_t done = 0;
    while (done < text.size()) {
      const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        const std::string msg = std::strerror(errno);
        ::close(fd);
        throw std::runtime_error(fmt::format("cannot write {}: {}", path_, msg));
      }
      done += static_cast<std::size_t>(n);
    }
    if (::close(fd) != 0)
      throw std::runtime_error(fmt::format("cannot write {}: {}", path_, std::strerror(errno)));
  }
  ~TemporaryScript() {
    if (!path_.empty()) ::unlink(path_.c_str());
  }
  TemporaryScript(const TemporaryScript&) = delete;
  TemporaryScript& operator=(const TemporaryScript&) = delete;

  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

// Runs argv[0] with these arguments and waits for it; returns its exit code, 128 + signal if a
// signal ended it. Like std::system, this process ignores Ctrl-C (SIGINT, SIGQUIT) meanwhile:
// the child, in the same process group, receives it and stops, and the temporary file is
// still removed.
int run_and_wait(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  for (const auto& a : args)
    argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);

  struct sigaction ignore {};
  ignore.sa_handler = SIG_IGN;
  sigemptyset(&ignore.sa_mask);
  struct sigaction old_int {
  }, old_quit{};
  sigaction(SIGINT, &ignore, &old_int);
  sigaction(SIGQUIT, &ignore, &old_quit);
  std::fflush(nullptr);  // nothing buffered here may be written twice by the child

  const pid_t pid = ::fork();
  if (pid == 0) {
    // The child: only async-signal-safe calls until execv.
    sigaction(SIGINT, &old_int, nullptr);
    sigaction(SIGQUIT, &old_quit, nullptr);
    // A SIGTERM or kill of crater ends the script as well (a sweep passes it on to its runs).
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);
    ::execv(argv[0], argv.data());
    const char msg[] = "crater: error: cannot start the Python interpreter\n";
    [[maybe_unused]] const ssize_t n = ::write(STDERR_FILENO, msg, sizeof msg - 1);
    ::_exit(127);
  }
  int status = 0;
  int result = kExitOther;
  if (pid < 0) {
    std::fprintf(stderr, "error: cannot start %s: %s\n", argv[0], std::strerror(errno));
  } else {
    pid_t w;
    do {
      w = ::waitpid(pid, &status, 0);
    } while (w < 0 && errno == EINTR);
    if (w == pid && WIFEXITED(status)) result = WEXITSTATUS(status);
    if (w == pid && WIFSIGNALED(status)) result = 128 + WTERMSIG(status);
  }
  sigaction(SIGINT, &old_int, nullptr);
  sigaction(SIGQUIT, &old_quit, nullptr);
  return result;
}

// The interpreter, or exit 1 naming the packages when it is missing.
bool have_python(const std::string& python, const char* command) {
  if (::access(python.c_str(), X_OK) == 0) return true;
  std::fprintf(stderr,
               "error: crater %s needs %s with the Debian packages %s (sudo apt-get install %s, "
               "or tools/setup-deps.sh)\n",
               command, python.c_str(), kDebianPackages, kDebianPackages);
  return false;
}

// This binary's own path, for the sweep script's runs.
std::string own_path() {
  std::error_code ec;
  const auto p = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::string("crater") : p.string();
}

}  // namespace

int cmd_report(const ReportOptions& opt) {
  const std::string python = python_path();
  if (!have_python(python, "report")) return kExitOther;
  std::error_code ec;
  if (std::filesystem::exists(std::filesystem::path(opt.run_dir) / "sweep.json", ec)) {
    // A sweep's directory: its charts and report.md.
    if (!opt.times.empty()) {
      std::fprintf(stderr,
                   "error: --times: %s is a sweep (sweep.json), whose report has no "
                   "snapshots\n",
                   opt.run_dir.c_str());
      return kExitInput;
    }
    const TemporaryScript script(kSweepScript);
    std::vector<std::string> args = {python,     script.path(), "--crater",
                                     own_path(), "--report",    opt.run_dir};
    if (!opt.out_dir.empty()) args.insert(args.end(), {"--out", opt.out_dir});
    if (!opt.metrics.empty()) args.insert(args.end(), {"--metrics", opt.metrics});
    return run_and_wait(args);
  }
  if (!opt.metrics.empty()) {
    std::fprintf(stderr, "error: --metrics: %s is a run, not a sweep (no sweep.json)\n",
                 opt.run_dir.c_str());
    return kExitInput;
  }
  const TemporaryScript script(kReportScript);
  std::vector<std::string> args = {python, script.path()};
  // "--out=VALUE" and "--": values that start with '-' are not taken for options
  if (!opt.out_dir.empty()) args.push_back("--out=" + opt.out_dir);
  if (!opt.times.empty()) args.push_back("--times=" + opt.times);
  args.insert(args.end(), {"--", opt.run_dir});
  return run_and_wait(args);
}

int cmd_sweep(const std::vector<std::string>& user_args) {
  const std::string python = python_path();
  if (!have_python(python, "sweep")) return kExitOther;
  const TemporaryScript script(kSweepScript);
  std::vector<std::string> args = {python, script.path(), "--crater", own_path()};
  args.insert(args.end(), user_args.begin(), user_args.end());
  return run_and_wait(args);
}

int cmd_verify(const std::vector<std::string>& user_args) {
  const std::string python = python_path();
  if (!have_python(python, "verify")) return kExitOther;
  const TemporaryScript script(kVerifyScript);
  // The cases sit beside the bundled scenarios: <prefix>/share/crater/{scenarios,verify} when
  // installed, <source>/{scenarios,verify} in a build tree.
  const auto cases = io::bundled_scenario_dir().parent_path() / "verify";
  std::vector<std::string> args = {python,     script.path(), "--crater",
                                   own_path(), "--cases-dir", cases.string()};
  args.insert(args.end(), user_args.begin(), user_args.end());
  return run_and_wait(args);
}

}  // namespace crater::app
