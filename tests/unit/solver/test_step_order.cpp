// The solver's step (solver/step.hpp) driven with stub parts that log every stage call: the
// order of Algorithm 1 (all parts advance, then the forces of the new state part by part, the
// contacts, every part checked, every part finishes), the times and steps each stage gets, a
// fault stopping the step before any part finishes it, and the stable step chosen over the
// parts' limits. The expected sequences are written out by hand from the algorithm's text.
#include <gtest/gtest.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "contact/coupling.hpp"
#include "core/error.hpp"
#include "solver/step.hpp"

namespace crater::solver {
namespace {

using Log = std::vector<std::string>;

/// A part that only records what the loop asks of it.
class LoggingPart final : public Part<2> {
 public:
  LoggingPart(std::string name, Log& log, StableStep step = {1e-3, 0, "stub"})
      : name_(std::move(name)), log_(log), step_(std::move(step)) {}

  const std::string& name() const override { return name_; }
  const char* method() const override { return "stub"; }
  Index count() const override { return 1; }
  Real mass_kg() const override { return 1; }
  StableStep stable_step() const override { return step_; }
  void compute_forces(Real t) override { log_.push_back(name_ + " forces t=" + fmt(t)); }
  std::optional<Fault> check() const override {
    log_.push_back(name_ + " check");
    if (faulty_) return Fault{7, "non-finite force"};
    return std::nullopt;
  }
  void advance(Real t, Real dt) override {
    log_.push_back(name_ + " advance t=" + fmt(t) + " dt=" + fmt(dt));
  }
  void finish_step(Real dt) override { log_.push_back(name_ + " finish dt=" + fmt(dt)); }
  Energies energies() const override { return {}; }
  Geometry<2> geometry() const override { return {}; }
  std::vector<fields::FieldView> point_fields() const override { return {}; }

  void make_faulty() { faulty_ = true; }

 private:
  static std::string fmt(Real v) { return std::to_string(v); }
  std::string name_;
  Log& log_;
  StableStep step_;
  bool faulty_ = false;
};

std::vector<std::unique_ptr<Part<2>>> two_parts(Log& log) {
  std::vector<std::unique_ptr<Part<2>>> parts;
  parts.push_back(std::make_unique<LoggingPart>("a", log));
  parts.push_back(std::make_unique<LoggingPart>("b", log));
  return parts;
}

std::string at(Real v) {
  return std::to_string(v);
}

TEST(SolverStepOrder, StagesRunInAlgorithmOrderOverAllParts) {
  Log log;
  auto parts = two_parts(log);
  contact::Coupling<2> coupling({}, parts);
  advance_stage(parts, 0.5, 0.25);
  finish_step_stages(parts, coupling, 0.75, 0.25);
  const Log expected = {
      "a advance t=" + at(0.5) + " dt=" + at(0.25),
      "b advance t=" + at(0.5) + " dt=" + at(0.25),
      "a forces t=" + at(0.75),
      "b forces t=" + at(0.75),
      "a check",
      "b check",
      "a finish dt=" + at(0.25),
      "b finish dt=" + at(0.25),
  };
  EXPECT_EQ(log, expected);
}

TEST(SolverStepOrder, FaultStopsTheStepBeforeAnyPartFinishes) {
  Log log;
  auto parts = two_parts(log);
  static_cast<LoggingPart&>(*parts[1]).make_faulty();
  contact::Coupling<2> coupling({}, parts);
  advance_stage(parts, 0.0, 0.5);
  try {
    finish_step_stages(parts, coupling, 0.5, 0.5);
    FAIL() << "a faulty part must stop the step";
  } catch (const NumericalError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("'b'"), std::string::npos) << what;
    EXPECT_NE(what.find("entity 7"), std::string::npos) << what;
    EXPECT_NE(what.find("non-finite force"), std::string::npos) << what;
  }
  for (const auto& line : log)
    EXPECT_EQ(line.find("finish"), std::string::npos) << "finished despite the fault: " << line;
  EXPECT_EQ(log.back(), "b check");
}

TEST(SolverStepOrder, SmallestAllowedStepWinsUnderTheSafetyFactor) {
  Log log;
  std::vector<std::unique_ptr<Part<2>>> parts;
  parts.push_back(std::make_unique<LoggingPart>("slow", log, StableStep{4e-6, 3, "CFL"}));
  parts.push_back(std::make_unique<LoggingPart>("fast", log, StableStep{2e-6, 5, "stiffness"}));
  // An accuracy bound is obeyed as it is: 1.9e-6 s allowed, while 2e-6 s x 0.9 = 1.8e-6 s.
  parts.push_back(
      std::make_unique<LoggingPart>("bound", log, StableStep{1.9e-6, 1, "bound", true}));
  contact::Coupling<2> coupling({}, parts);
  const StepLimit<2> lim = smallest_stable_step(parts, &coupling, 0.9);
  EXPECT_EQ(lim.part, "fast");
  EXPECT_EQ(lim.who, "part 'fast'");
  EXPECT_DOUBLE_EQ(lim.dt_s, 2e-6);
  EXPECT_DOUBLE_EQ(lim.allowed_s, 0.9 * 2e-6);
  EXPECT_EQ(lim.detail.entity_id, 5);
  // At safety factor 1 (the limits as stated, which a fixed step must respect) the accuracy
  // bound is the smallest.
  const StepLimit<2> stated = smallest_stable_step(parts, &coupling, 1.0);
  EXPECT_EQ(stated.part, "bound");
  EXPECT_DOUBLE_EQ(stated.allowed_s, 1.9e-6);
}

TEST(SolverStepOrder, FixedStepAboveTheLimitIsAnInputErrorNamingThePart) {
  Log log;
  std::vector<std::unique_ptr<Part<2>>> parts;
  parts.push_back(std::make_unique<LoggingPart>("plate", log, StableStep{1e-7, 42, "element"}));
  contact::Coupling<2> coupling({}, parts);
  io::Config c;
  c.time.fixed_dt_s = 1e-6;
  const StepLimit<2> lim = smallest_stable_step(parts, &coupling, 1.0);
  try {
    check_fixed_step(c, lim);
    FAIL() << "a fixed step above the stable limit must be refused";
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "time.fixed_dt_s");
    const std::string what = e.what();
    EXPECT_NE(what.find("part 'plate'"), std::string::npos) << what;
    EXPECT_NE(what.find("entity 42"), std::string::npos) << what;
  }
  c.time.fixed_dt_s = 1e-7;  // at the limit: accepted
  EXPECT_NO_THROW(check_fixed_step(c, lim));
}

}  // namespace
}  // namespace crater::solver
