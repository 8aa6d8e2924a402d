#include "steadiface_ros/render_worker.h"

#include <utility>

namespace steadiface_ros {

RenderWorker::~RenderWorker() {
  {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [this] { return !has_job_; });
    stop_ = true;
  }
  changed_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void RenderWorker::Start(std::function<void()> job) {
  Wait();
  if (!thread_.joinable()) thread_ = std::thread([this] { Run(); });
  {
    std::lock_guard<std::mutex> lock(mutex_);
    job_ = std::move(job);
    has_job_ = true;
  }
  changed_.notify_all();
}

void RenderWorker::Wait() {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [this] { return !has_job_; });
}

void RenderWorker::Run() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    changed_.wait(lock, [this] { return has_job_ || stop_; });
    if (has_job_) {
      std::function<void()> job = std::move(job_);
      lock.unlock();
      job();
      lock.lock();
      has_job_ = false;
      changed_.notify_all();
    } else if (stop_) {
      return;
    }
  }
}

}  // namespace steadiface_ros
