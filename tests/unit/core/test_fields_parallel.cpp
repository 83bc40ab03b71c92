// FieldSet (structure-of-arrays registry), deterministic reductions, JSON writer.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include "fields/field_set.hpp"
#include "io/output/json.hpp"
#include "parallel/parallel.hpp"

namespace {

using crater::Index;
using crater::Real;

TEST(FieldSet, PermuteMovesEveryFieldTogether) {
  crater::fields::FieldSet<2> f;
  auto& id = f.add_integer("id", "1", crater::fields::kOutput);
  auto& x = f.add_vector("position", "m", crater::fields::kRestart);
  auto& rho = f.add_scalar("density", "kg/m^3", crater::fields::kOutput);
  f.resize(4);
  for (Index i = 0; i < 4; ++i) {
    id[i] = i;
    x[i] = crater::Vec<2>(i, -i);
    rho[i] = 10.0 * i;
  }
  const std::vector<Index> order{2, 0, 3, 1};
  f.permute(order);
  for (Index i = 0; i < 4; ++i) {
    EXPECT_EQ(id[i], order[i]);
    EXPECT_EQ(x[i][0], static_cast<Real>(order[i]));
    EXPECT_EQ(x[i][1], -static_cast<Real>(order[i]));
    EXPECT_EQ(rho[i], 10.0 * order[i]);
  }
  EXPECT_THROW(f.permute(std::vector<Index>{0, 1}), std::logic_error);
}

TEST(FieldSet, CompactDropsMaskedEntitiesAndKeepsTheOrderOfTheRest) {
  crater::fields::FieldSet<2> f;
  auto& id = f.add_integer("id", "1", crater::fields::kOutput);
  auto& x = f.add_vector("position", "m", crater::fields::kRestart);
  auto& rho = f.add_scalar("density", "kg/m^3", crater::fields::kOutput);
  f.resize(6);
  for (Index i = 0; i < 6; ++i) {
    id[i] = i;
    x[i] = crater::Vec<2>(i, -i);
    rho[i] = 10.0 * i;
  }
  const std::vector<std::uint8_t> keep{0, 1, 1, 0, 0, 1};
  EXPECT_EQ(f.compact(keep), 3);
  EXPECT_EQ(f.size(), 3);
  const std::vector<Index> kept{1, 2, 5};
  for (Index i = 0; i < 3; ++i) {  // every field compacted alike, in index order
    EXPECT_EQ(id[i], kept[i]);
    EXPECT_EQ(x[i][0], static_cast<Real>(kept[i]));
    EXPECT_EQ(x[i][1], -static_cast<Real>(kept[i]));
    EXPECT_EQ(rho[i], 10.0 * kept[i]);
  }
  for (const auto& v : f.views(crater::fields::kOutput | crater::fields::kRestart))
    EXPECT_EQ(v.size, 3);
  EXPECT_EQ(id.size(), 3u);
  EXPECT_EQ(x.size(), 3u);
  EXPECT_THROW(f.compact(std::vector<std::uint8_t>{1, 1}), std::logic_error);
  EXPECT_EQ(f.compact(std::vector<std::uint8_t>{1, 1, 1}), 3);  // keep all: unchanged
  EXPECT_EQ(id[2], 5);
  EXPECT_EQ(f.compact(std::vector<std::uint8_t>{0, 0, 0}), 0);  // remove all
  EXPECT_TRUE(rho.empty());
  f.resize(1);  // an emptied set still grows
  EXPECT_EQ(rho[0], 0.0);
}

TEST(FieldSet, ViewsFilterByRoleAndKeepReferencesStable) {
  crater::fields::FieldSet<3> f;
  auto& a = f.add_scalar("a", "1", crater::fields::kOutput);
  f.add_scalar("b", "1", crater::fields::kRestart);
  auto& v = f.add_vector("v", "m/s", crater::fields::kOutput | crater::fields::kRestart);
  f.resize(3);
  a[2] = 5.0;  // references taken before later registrations and resize stay valid
  v[1] = crater::Vec<3>(1, 2, 3);
  const auto out = f.views(crater::fields::kOutput);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].info->name, "a");
  EXPECT_EQ(out[0].real_data[2], 5.0);
  EXPECT_EQ(out[1].components, 3);
  EXPECT_EQ(out[1].real_data[3 * 1 + 2], 3.0);
  EXPECT_THROW(f.add_scalar("a", "1", 0), std::logic_error);
}

TEST(Parallel, DeterministicSumIsBitIdenticalAcrossThreadCounts) {
  // Values spanning many magnitudes make any change of association order visible.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<Real> u(-1, 1);
  std::vector<Real> v(100003);
  for (auto& x : v)
    x = u(rng) * std::pow(10.0, 12 * u(rng));
  auto sum_with = [&](int threads) {
    omp_set_num_threads(threads);
    return crater::parallel::deterministic_sum<Real>(static_cast<Index>(v.size()),
                                                     [&](Index i) { return v[i]; });
  };
  const Real s1 = sum_with(1), s2 = sum_with(2), s3 = sum_with(3);
  EXPECT_EQ(std::memcmp(&s1, &s2, sizeof s1), 0);
  EXPECT_EQ(std::memcmp(&s1, &s3, sizeof s1), 0);
  // And it is a sum: compare with a compensated serial sum.
  long double ref = 0;
  for (Real x : v)
    ref += x;
  EXPECT_NEAR(s1, static_cast<Real>(ref), 1e-9 * std::abs(static_cast<Real>(ref)) + 1e3);
}

TEST(Parallel, SumIfSkipsZerosBitForBit) {
  // Two thirds of the terms are +0 (a wall's load on the grains not touching it): summing only
  // the others gives deterministic_sum's bits, on any thread count. One term is -0, kept.
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<Real> u(-1, 1);
  std::vector<Real> v(100003, 0.0);
  for (std::size_t i = 0; i < v.size(); i += 3)
    v[i] = u(rng) * std::pow(10.0, 12 * u(rng));
  v[3] = -0.0;
  const auto n = static_cast<Index>(v.size());
  const auto term = [&](Index i) { return v[static_cast<std::size_t>(i)]; };
  const auto kept = [](Index i) { return i % 3 == 0; };
  omp_set_num_threads(1);
  const Real all = crater::parallel::deterministic_sum<Real>(n, term);
  for (const int threads : {1, 2, 3}) {
    omp_set_num_threads(threads);
    const Real some = crater::parallel::deterministic_sum_if<Real>(n, kept, term);
    EXPECT_EQ(std::memcmp(&all, &some, sizeof all), 0) << threads << " threads";
  }
}

TEST(Parallel, SelectKeepsTheIndicesInOrderForAnyThreadCount) {
  // Several reduction blocks, a ragged last one, runs of kept and dropped indices.
  std::mt19937_64 rng(11);
  std::bernoulli_distribution keep(0.03);
  const Index n = 3 * crater::parallel::kReduceBlock + 517;
  std::vector<char> flag(static_cast<std::size_t>(n));
  for (auto& f : flag)
    f = keep(rng);
  // A long run of kept indices across a block's end (it was 5000-9000, past the end of the
  // vector since the block became 512: GCC's -Wstringop-overflow said so).
  const Index run_lo = crater::parallel::kReduceBlock + 100;
  const Index run_hi = 2 * crater::parallel::kReduceBlock + 100;
  ASSERT_LT(run_hi, n);
  std::fill(flag.begin() + run_lo, flag.begin() + run_hi, char{1});
  std::vector<Index> expected;
  for (Index i = 0; i < n; ++i)
    if (flag[static_cast<std::size_t>(i)]) expected.push_back(i);
  for (int threads : {1, 2, 3}) {
    omp_set_num_threads(threads);
    EXPECT_EQ(crater::parallel::select(n, [&](Index i) { return flag[i] != 0; }), expected);
  }
  EXPECT_TRUE(crater::parallel::select(0, [](Index) { return true; }).empty());
  EXPECT_EQ(crater::parallel::select(3, [](Index i) { return i != 1; }),
            (std::vector<Index>{0, 2}));
}

TEST(Parallel, MinMaxOver) {
  std::vector<Real> v{3, -1, 7, 2};
  EXPECT_EQ(crater::parallel::min_over(4, 1e300, [&](Index i) { return v[i]; }), -1);
  EXPECT_EQ(crater::parallel::max_over(4, -1e300, [&](Index i) { return v[i]; }), 7);
  EXPECT_EQ(crater::parallel::max_over(0, -5.0, [&](Index i) { return v[i]; }), -5.0);
}

TEST(JsonWriter, NestedObjectsArraysEscapesAndNonFinite) {
  crater::io::JsonWriter j;
  j.begin_object();
  j.field("name", "a\"b\\c\n");
  j.key("list").begin_array();
  j.value(1.5).value(std::int64_t{2}).value(std::nan(""));
  j.end_array();
  j.key("empty").begin_object();
  j.end_object();
  j.field("ok", true);
  j.end_object();
  EXPECT_EQ(j.str(),
            "{\n  \"name\": \"a\\\"b\\\\c\\n\",\n  \"list\": [\n    1.5,\n    2,\n    null\n  ],"
            "\n  \"empty\": {},\n  \"ok\": true\n}\n");
}

}  // namespace
