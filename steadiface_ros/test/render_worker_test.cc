// RenderWorker: every job runs, in order, on one thread that is not the
// caller's; Wait() returns only after the job has run; the destructor runs
// the job in hand before joining.
#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "steadiface_ros/render_worker.h"

namespace steadiface_ros {
namespace {

TEST(RenderWorkerTest, RunsEveryJobInOrderOnOneOtherThread) {
  std::vector<int> order;
  std::vector<std::thread::id> ids;
  {
    RenderWorker worker;
    worker.Wait();  // idle: returns at once
    for (int i = 0; i < 50; ++i) {
      worker.Start([&order, &ids, i] {
        if (i % 7 == 0)
          std::this_thread::sleep_for(std::chrono::milliseconds(2));
        order.push_back(i);  // Start() waits for the previous job first
        ids.push_back(std::this_thread::get_id());
      });
      if (i % 2 == 0) {
        worker.Wait();
        ASSERT_EQ(order.size(), static_cast<size_t>(i + 1));
        EXPECT_EQ(order.back(), i);
      }
    }
  }  // the destructor runs job 49 before joining
  ASSERT_EQ(order.size(), 50u);
  for (int i = 0; i < 50; ++i) EXPECT_EQ(order[i], i);
  for (const auto& id : ids) {
    EXPECT_EQ(id, ids[0]);
    EXPECT_NE(id, std::this_thread::get_id());
  }
}

TEST(RenderWorkerTest, WaitReturnsOnlyAfterASlowJob) {
  RenderWorker worker;
  std::atomic<bool> done{false};
  worker.Start([&done] {
    std::this_thread::sleep_for(std::chrono::milliseconds(30));
    done = true;
  });
  worker.Wait();
  EXPECT_TRUE(done);
}

}  // namespace
}  // namespace steadiface_ros
