// Unit tests of the particle-part kit: outflow removal (src/parts/outflow.hpp), the contact
// work ledger (src/parts/contact_points.hpp) and the index helper (src/core/index.hpp).
#include <gtest/gtest.h>

#include <vector>

#include "core/index.hpp"
#include "fields/field_set.hpp"
#include "parts/contact_points.hpp"
#include "parts/outflow.hpp"

namespace crater::parts {
namespace {

TEST(IndexHelper, PositionOfAnIndex) {
  EXPECT_EQ(at(Index{0}), std::size_t{0});
  EXPECT_EQ(at(Index{41}), std::size_t{41});
}

TEST(InBox, ClosedBoxAndNaN) {
  const Vec<2> lo(0, 0), hi(1, 2);
  EXPECT_TRUE(in_box<2>(Vec<2>(0, 2), lo, hi));  // faces belong to the box
  EXPECT_FALSE(in_box<2>(Vec<2>(1.5, 1), lo, hi));
  EXPECT_FALSE(in_box<2>(Vec<2>(0.5, std::nan("")), lo, hi));
}

// Survivors keep their order; the ledger adds up what left; a checkpoint round trip keeps it.
TEST(OutflowRemoval, CompactsInIndexOrderAndBooks) {
  fields::FieldSet<2> f;
  auto& id = f.add_integer("id", "1", fields::kRestart);
  auto& m = f.add_scalar("mass", "kg", fields::kRestart);
  f.resize(6);
  for (Index i = 0; i < 6; ++i) {
    id[at(i)] = i;
    m[at(i)] = Real(i + 1);
  }
  OutflowRemoval out;
  const Index leaving = out.mark(6, [](Index i) { return i % 3 != 1; });  // 1 and 4 leave
  ASSERT_EQ(leaving, 2);
  EXPECT_FALSE(out.kept(1));
  EXPECT_TRUE(out.kept(2));
  const auto removed = parallel::deterministic_sum<Removed>(6, [&](Index i) {
    return out.kept(i) ? Removed{} : Removed{m[at(i)], 10 * m[at(i)]};
  });
  out.book("p", "particles", 0.5, leaving, removed);
  EXPECT_EQ(out.compact(f), 4);
  EXPECT_EQ(id, (std::vector<std::int64_t>{0, 2, 3, 5}));
  EXPECT_EQ(out.count(), 2);
  EXPECT_DOUBLE_EQ(out.mass_kg(), 2 + 5);
  EXPECT_DOUBLE_EQ(out.energy_j(), 70);

  std::vector<Diagnostic> d;
  out.add_diagnostics(d);
  ASSERT_EQ(d.size(), 3u);
  EXPECT_EQ(d[0].name, "left_domain_count");
  EXPECT_EQ(d[0].value, 2);

  StateWriter w;
  out.save(w);
  OutflowRemoval back;
  StateReader r(w.bytes(), "test");
  back.load(r);
  EXPECT_TRUE(r.done());
  EXPECT_EQ(back.count(), 2);
  EXPECT_EQ(back.mass_kg(), out.mass_kg());
  EXPECT_EQ(back.energy_j(), out.energy_j());
}

// The work of the contact forces over a step: dt/2 sum v . (F + F'), once per advance, over the
// own entities only (a rank's ghosts are their owners' to book).
TEST(ContactWork, TrapezoidalOncePerAdvance) {
  const parallel::Comm one;
  const auto all = [](Index) { return true; };
  ContactWork cw;
  cw.settle(
      one, 3, [](Index) { return 1.0; }, all);  // not moved yet: nothing
  EXPECT_EQ(cw.work_j, 0);
  cw.moved(0.2);
  cw.settle(
      one, 3, [](Index i) { return Real(i); }, all);  // 0 + 1 + 2
  EXPECT_DOUBLE_EQ(cw.work_j, 0.1 * 3);
  cw.settle(
      one, 3, [](Index) { return 5.0; }, all);  // same step again: nothing more
  EXPECT_DOUBLE_EQ(cw.work_j, 0.1 * 3);
  EXPECT_FALSE(cw.pending);
  cw.moved(0.2);
  cw.settle(
      one, 4, [](Index i) { return Real(i + 1); }, [](Index i) { return i % 2 == 0; });
  EXPECT_DOUBLE_EQ(cw.work_j, 0.1 * 3 + 0.1 * (1 + 3));  // entities 0 and 2 alone
}

}  // namespace
}  // namespace crater::parts
