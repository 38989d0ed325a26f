#include "clothlab/core/threads.hpp"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <system_error>

#include <fmt/format.h>

namespace clothlab {

namespace {

// Waits until done() holds: a short spin first (a step's jobs follow each other within
// microseconds), then yielding the core, so that a thread waiting between runs does not take
// it from a build or another program.
template <class Done>
void wait_until(Done done) {
  for (int spin = 0; spin < 2000; ++spin) {
    if (done()) return;
  }
  const auto start = std::chrono::steady_clock::now();
  while (!done()) {
    if (std::chrono::steady_clock::now() - start < std::chrono::microseconds(200)) {
      std::this_thread::yield();
    } else {
      return;  // the caller falls back to a blocking wait
    }
  }
}

}  // namespace

ThreadTeam::ThreadTeam(int size) : size_(std::max(1, size)) {
  try {
    for (int t = 1; t < size_; ++t)
      workers_.emplace_back([this, t] { work(t); });
  } catch (const std::system_error& error) {
    // The system would not start another thread (a limit on processes, or on memory): stop the
    // ones that started and say so, rather than end the program with threads still running.
    const size_t started = workers_.size() + 1;
    stop();
    throw std::runtime_error(fmt::format(
        "could not start thread {} of the {} asked for ({}); ask for fewer with [engine] threads "
        "or --threads",
        started + 1, size_, error.what()));
  }
}

void ThreadTeam::stop() {
  stop_.store(true);
  generation_.fetch_add(1);
  generation_.notify_all();
  for (std::thread& worker : workers_)
    worker.join();
  workers_.clear();
}

ThreadTeam::~ThreadTeam() {
  stop();
}

int ThreadTeam::hardware_threads() {
  return std::max(1u, std::thread::hardware_concurrency());
}

void ThreadTeam::record(std::exception_ptr error) {
  const std::lock_guard<std::mutex> lock(error_mutex_);
  if (!error_) error_ = error;
}

void ThreadTeam::run(const std::function<void(int)>& job) {
  ++runs_;
  if (size_ == 1) {
    job(0);
    return;
  }
  job_ = &job;
  error_ = nullptr;
  busy_.store(size_ - 1);
  generation_.fetch_add(1);  // publishes job_ to the workers
  generation_.notify_all();
  try {
    job(0);
  } catch (...) {
    record(std::current_exception());
  }
  wait_until([&] { return busy_.load() == 0; });
  for (int busy = busy_.load(); busy != 0; busy = busy_.load())
    busy_.wait(busy);
  job_ = nullptr;
  if (error_) std::rethrow_exception(error_);
}

void ThreadTeam::work(int t) {
  unsigned seen = 0;
  for (;;) {
    wait_until([&] { return generation_.load() != seen; });
    for (unsigned now = generation_.load(); now == seen; now = generation_.load())
      generation_.wait(now);
    seen = generation_.load();
    if (stop_.load()) return;
    try {
      (*job_)(t);
    } catch (...) {
      record(std::current_exception());
    }
    if (busy_.fetch_sub(1) == 1) busy_.notify_one();
  }
}

}  // namespace clothlab
