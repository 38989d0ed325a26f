// threads.hpp: a small team of threads that a step's passes over the particles are split over.
//
// The team is made once (World keeps it) and sleeps between jobs, so a step pays for waking the
// threads, not for starting them. The work is split by the caller, never by the team: each
// thread gets a contiguous range of particles, and a step's result does not depend on how many
// threads took it (see engine/fast/engine.hpp).
//
// A job that must wait, half way, for every thread to finish a first part (a pass that reads
// what the others' first part wrote) calls sync() there: the threads meet without being put to
// sleep and woken again, so the two parts cost one wake, not two.
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

  // Inside a job of run(), on every thread of the team: returns once every thread has called it
  // as often as this one (a barrier within the job; no thread sleeps for it unless it waits
  // long). Every thread's job must call it the same number of times. If a job throws on one
  // thread, the others stop waiting here and end their jobs, and run() rethrows the error.
  // With `last`, the last thread to arrive calls last() before any thread leaves: work that must
  // be done once, by one thread, between the two parts (the next step's time), at no second
  // meeting. On one thread, last() is called at once. If it throws, the error is the job's.
  void sync(const std::function<void()>& last = {});

  // The threads this machine can run at once (at least 1).
  static int hardware_threads();

 private:
  void work(int t);
  void stop();  // ends and joins the workers
  // Keeps the first error of a job and releases the threads waiting in sync().
  void record(std::exception_ptr error);
  void job_of(int t);  // runs job_(t), recording what it throws

  int size_;
  long runs_ = 0;
  const std::function<void(int)>* job_ = nullptr;
  std::atomic<unsigned> generation_{0};  // one more for every job handed out
  std::atomic<int> busy_{0};             // workers still running the current job
  std::atomic<bool> stop_{false};
  // sync(): the threads that have reached it in this round, and the rounds completed (each
  // thread waits for the count of rounds to move). failed_: a job threw, nobody waits more.
  std::atomic<int> arrived_{0};
  std::atomic<unsigned> rounds_{0};
  std::atomic<bool> failed_{false};
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

// The even split of [0, n) into `parts` pieces: bounds[t] = n t / parts for t = 0 .. parts, so
// piece t is [bounds[t], bounds[t + 1]).
std::vector<Index> even_bounds(Index n, int parts);

// for_ranges on pieces given by their bounds (team->size() + 1 of them, as even_bounds makes):
// range(bounds[t], bounds[t + 1]) on thread t, or the whole of [bounds.front(), bounds.back())
// on this thread when team is null.
template <class Range>
void for_bounds(ThreadTeam* team, const std::vector<Index>& bounds, const Range& range) {
  if (!team || team->size() == 1) {
    range(bounds.front(), bounds.back());
    return;
  }
  team->run(
      [&](int t) { range(bounds[static_cast<size_t>(t)], bounds[static_cast<size_t>(t) + 1]); });
}

// Moves the inner bounds of the pieces toward the split in which every piece would take the same
// time, were the work measured on each (work[t] for piece t, in any unit) spread evenly over its
// items: the pieces of a pass whose items cost unequal amounts (a cloth whose contacts lie in
// one thread's particles) even out over the passes that follow. Nothing moves while the busiest
// piece is within `tolerance` of the mean (0.03: three percent), so that a balanced pass's
// timing noise does not shift it back and forth; each bound moves half way to where it should
// be, by at most max_shift items, so that one piece slowed once by something else (another
// program on its core) moves the split little; a bound it moves lands on a multiple of `align`
// (pieces that share no cache line), and pieces keep their order. Returns whether a bound moved.
bool balance_bounds(std::vector<Index>& bounds, const std::vector<double>& work, Index align,
                    Index max_shift, double tolerance);

// What a range of for_ranges_with_barrier may wait at: wait() returns once every thread of the
// job has reached it (ThreadTeam::sync); on one thread it returns at once. wait(last) calls
// last() once, on the last thread to arrive, before any leaves (on one thread, at once).
class Barrier {
 public:
  // waited: if not null, the seconds this thread spends in wait() are added there.
  explicit Barrier(ThreadTeam* team, double* waited = nullptr) : team_(team), waited_(waited) {}
  void wait(const std::function<void()>& last = {}) const;

 private:
  ThreadTeam* team_;
  double* waited_;
};

// Where the threads' time went in the jobs of for_ranges_with_barrier, summed over the jobs, for
// `clothlab bench roofline`, which asks why two threads do not take half one's time. A thread's
// work in a job is its time in the job less its waits at the barrier.
struct ThreadProfile {
  long jobs = 0;
  double wall = 0.0;     // [s] each job, from the call to the return, as the caller waited for it
  double busiest = 0.0;  // [s] the work of the thread that worked longest in each job
  double busy = 0.0;     // [s] the threads' work in each job, averaged over the threads
};

// for_ranges, where range(begin, end, barrier) may call barrier.wait() between two parts of its
// work that must not overlap across threads: all of it one job, one wake of the threads. Every
// range must call it the same number of times, an empty range too. With a profile, each job
// adds its times there (two clock reads a thread and a wait more).
// The pieces are given by their bounds (for_bounds). With `work`, each thread's work in the job
// (its time less its waits at the barrier, in seconds) is left in (*work)[t].
void for_ranges_with_barrier(
    ThreadTeam* team, const std::vector<Index>& bounds,
    const std::function<void(Index begin, Index end, const Barrier& barrier)>& range,
    ThreadProfile* profile = nullptr, std::vector<double>* work = nullptr);

}  // namespace clothlab
