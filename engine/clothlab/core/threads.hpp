// threads.hpp: a small team of threads that a step's passes over the particles are split over.
//
// The team is made once (World keeps it) and sleeps between jobs, so a step pays for waking the
// threads, not for starting them. The work is split by the caller, never by the team: each
// thread gets a contiguous range of particles, and a step's result does not depend on how many
// threads took it (see engine/fast/engine.hpp).
#pragma once

#include <atomic>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "clothlab/core/types.hpp"

namespace clothlab {

class ThreadTeam {
 public:
  explicit ThreadTeam(int size);  // size - 1 threads are started; the caller is the last one
  ~ThreadTeam();
  ThreadTeam(const ThreadTeam&) = delete;
  ThreadTeam& operator=(const ThreadTeam&) = delete;

  int size() const { return size_; }

  // Runs job(t) for t = 0, 1, ..., size() - 1, job(0) on the calling thread, and returns when
  // every one has returned. If jobs threw, the first exception is rethrown here.
  void run(const std::function<void(int)>& job);

  // The jobs run() has been given so far: each wakes the threads once and waits for them all
  // (a barrier), the cost a step pays per pass over the particles (bench methods --speed).
  long runs() const { return runs_; }

  // The threads this machine can run at once (at least 1).
  static int hardware_threads();

 private:
  void work(int t);
  void stop();  // ends and joins the workers
  void record(std::exception_ptr error);

  int size_;
  long runs_ = 0;
  const std::function<void(int)>* job_ = nullptr;
  std::atomic<unsigned> generation_{0};  // one more for every job handed out
  std::atomic<int> busy_{0};             // workers still running the current job
  std::atomic<bool> stop_{false};
  std::mutex error_mutex_;
  std::exception_ptr error_;
  std::vector<std::thread> workers_;
};

// Calls range(begin, end) on contiguous pieces that cover [0, n) once each: the whole of it on
// this thread when team is null, else piece t of team->size() on thread t.
template <class Range>
void for_ranges(ThreadTeam* team, Index n, const Range& range) {
  if (!team || team->size() == 1) {
    range(Index{0}, n);
    return;
  }
  const Index parts = team->size();
  team->run([&](int t) { range(n * t / parts, n * (t + 1) / parts); });
}

}  // namespace clothlab
