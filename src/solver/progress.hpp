// The progress line: a live line on a terminal (percent, simulated time, steps/s, ETA, and on
// MPI ranks their load balance), plain log lines every few seconds when stderr is not a
// terminal.
#pragma once

#include <fmt/format.h>
#include <unistd.h>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>
#include <string>

#include "core/types.hpp"

namespace crater::solver {

class Progress {
 public:
  /// first_step, first_t_s: where this run starts (non-zero on a resumed run), so that steps/s
  /// and the ETA count only the work done by this process.
  /// `note`, if set, is asked for a text to end each line with (the ranks' load balance).
  Progress(Real end_time_s, bool quiet, Index first_step, Real first_t_s,
           std::function<std::string()> note = {})
      : note_(std::move(note)),
        end_s_(end_time_s),
        first_step_(first_step),
        first_t_s_(first_t_s),
        quiet_(quiet),
        tty_(::isatty(2) == 1),
        start_(Clock::now()),
        last_(start_) {}

  void update(Index step, Real t_s, Real dt_s) {
    if (quiet_) return;
    const auto now = Clock::now();
    const double since = seconds(now - last_);
    if (since < (tty_ ? 0.25 : 10.0)) return;
    last_ = now;
    print(step, t_s, dt_s, now, false);
  }

  void finish(Index step, Real t_s, Real dt_s) {
    if (quiet_) return;
    print(step, t_s, dt_s, Clock::now(), true);
  }

 private:
  using Clock = std::chrono::steady_clock;
  static double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

  void print(Index step, Real t_s, Real dt_s, Clock::time_point now, bool done) {
    const double wall = seconds(now - start_);
    const double frac = end_s_ > 0 ? std::min(1.0, t_s / end_s_) : 1.0;
    const double rate = wall > 0 ? static_cast<double>(step - first_step_) / wall : 0.0;
    const double done_s = t_s - first_t_s_;
    const double eta = done_s > 0 ? wall * std::max(0.0, end_s_ - t_s) / done_s : 0.0;
    const std::string line =
        fmt::format("{:5.1f} %  t = {:.4e} s  step {}  dt = {:.3e} s  {:.0f} steps/s  {}{}",
                    100 * frac, t_s, step, dt_s, rate,
                    done ? fmt::format("wall {:.1f} s", wall) : fmt::format("ETA {:.0f} s", eta),
                    note_ ? note_() : std::string());
    if (tty_)
      std::fprintf(stderr, "\r%s\033[K%s", line.c_str(), done ? "\n" : "");
    else
      std::fprintf(stderr, "crater: %s\n", line.c_str());
    std::fflush(stderr);
  }

  std::function<std::string()> note_;
  Real end_s_;
  Index first_step_;
  Real first_t_s_;
  bool quiet_;
  bool tty_;
  Clock::time_point start_, last_;
};

}  // namespace crater::solver
