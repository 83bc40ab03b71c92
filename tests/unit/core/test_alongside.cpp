// parallel::alongside (parallel/parallel.hpp): the main thread's task beside blocks dealt to the
// team. Checked: every block runs exactly once whatever the thread count and chunk, the task
// runs once on the calling thread and what it forks runs on that thread alone, one thread runs
// the task then the blocks in order, and an exception from either side reaches the caller only
// after every block has returned.
#include <gtest/gtest.h>
#include <omp.h>

#include <atomic>
#include <stdexcept>
#include <vector>

#include "parallel/parallel.hpp"

namespace {

using crater::Index;
namespace parallel = crater::parallel;

// Restores the thread count the suite runs with.
class Alongside : public ::testing::Test {
 protected:
  void TearDown() override { parallel::set_threads(threads_); }
  int threads_ = parallel::max_threads();
};

TEST_F(Alongside, EveryBlockOnceAndTheTaskOnTheCallingThread) {
  for (const int threads : {1, 2, 3}) {
    parallel::set_threads(threads);
    for (const Index chunk : {Index{1}, Index{4}, Index{7}}) {
      const Index blocks = 1001;
      std::vector<std::atomic<int>> runs(static_cast<std::size_t>(blocks));
      int task_runs = 0, task_thread = -1, inner_team = 0;
      parallel::alongside(
          blocks, chunk,
          [&] {
            ++task_runs;
            task_thread = omp_get_thread_num();
        // A loop the task forks: a region inside the region, of one thread.
#pragma omp parallel
            {
#pragma omp atomic
              ++inner_team;
            }
          },
          [&](Index b) { runs[static_cast<std::size_t>(b)].fetch_add(1); });
      SCOPED_TRACE(testing::Message() << threads << " threads, chunk " << chunk);
      EXPECT_EQ(task_runs, 1);
      EXPECT_EQ(task_thread, 0);
      EXPECT_EQ(inner_team, 1);
      for (Index b = 0; b < blocks; ++b)
        ASSERT_EQ(runs[static_cast<std::size_t>(b)].load(), 1) << "block " << b;
    }
  }
}

TEST_F(Alongside, OneThreadRunsTheTaskThenTheBlocksInOrder) {
  parallel::set_threads(1);
  std::vector<Index> order;
  parallel::alongside(
      5, 2, [&] { order.push_back(-1); }, [&](Index b) { order.push_back(b); });
  EXPECT_EQ(order, (std::vector<Index>{-1, 0, 1, 2, 3, 4}));
}

TEST_F(Alongside, NoBlocksRunsTheTaskAlone) {
  parallel::set_threads(2);
  int task_runs = 0, block_runs = 0;
  parallel::alongside(
      0, 4, [&] { ++task_runs; }, [&](Index) { ++block_runs; });
  EXPECT_EQ(task_runs, 1);
  EXPECT_EQ(block_runs, 0);
}

TEST_F(Alongside, ExceptionsReachTheCallerAfterEveryBlock) {
  for (const int threads : {1, 2}) {
    parallel::set_threads(threads);
    SCOPED_TRACE(testing::Message() << threads << " threads");
    std::atomic<int> block_runs{0};
    EXPECT_THROW(parallel::alongside(
                     64, 4, [] { throw std::runtime_error("task"); },
                     [&](Index) { block_runs.fetch_add(1); }),
                 std::runtime_error);
    EXPECT_EQ(block_runs.load(), 64);
    block_runs = 0;
    try {
      parallel::alongside(
          64, 4, [] {},
          [&](Index b) {
            block_runs.fetch_add(1);
            if (b == 17) throw std::logic_error("block 17");
          });
      ADD_FAILURE() << "a block's exception must reach the caller";
    } catch (const std::logic_error& e) {
      EXPECT_STREQ(e.what(), "block 17");
    }
    EXPECT_EQ(block_runs.load(), 64);
    // Both throw: the task's is the one rethrown.
    EXPECT_THROW(parallel::alongside(
                     8, 1, [] { throw std::runtime_error("task"); },
                     [](Index) { throw std::logic_error("block"); }),
                 std::runtime_error);
  }
}

}  // namespace
