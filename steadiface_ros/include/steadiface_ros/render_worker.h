#pragma once

#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>

namespace steadiface_ros {

/// One long-lived thread that runs one job at a time, for the wrapper's
/// pipelined rendering: Start() hands a job over, Wait() blocks until it
/// has run. It replaces a thread created and joined per frame. The thread
/// starts on the first Start() and is joined by the destructor (after the
/// job in hand, if any, has run).
///
/// Threading: Start() and Wait() are called from one owner thread; Start()
/// only after the previous job was waited for.
class RenderWorker {
 public:
  RenderWorker() = default;
  ~RenderWorker();
  RenderWorker(const RenderWorker&) = delete;
  RenderWorker& operator=(const RenderWorker&) = delete;

  /// Runs `job` on the worker thread. Waits first for a job still running.
  void Start(std::function<void()> job);
  /// Returns once the last started job has run (at once when idle).
  void Wait();

 private:
  void Run();

  std::mutex mutex_;
  std::condition_variable changed_;
  std::function<void()> job_;
  bool has_job_ = false;  // a job is handed over and has not finished
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace steadiface_ros
