#include "clothlab/core/threads.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
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

// Thrown by sync() on the threads that were waiting there for a job that threw on another
// thread: it ends their jobs, and run() rethrows the other thread's error, not this.
struct Abandoned {};

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
  {
    const std::lock_guard<std::mutex> lock(error_mutex_);
    if (!error_) error_ = error;
  }
  // The threads waiting in sync() for this one would wait forever: move the round on, so that
  // they look, and find failed_.
  failed_.store(true);
  rounds_.fetch_add(1);
  rounds_.notify_all();
}

void ThreadTeam::job_of(int t) {
  try {
    (*job_)(t);
  } catch (const Abandoned&) {
    // Another thread's job threw: its error is the one recorded.
  } catch (...) {
    record(std::current_exception());
  }
}

void ThreadTeam::sync(const std::function<void()>& last) {
  if (size_ == 1) {
    if (last) last();
    return;
  }
  // The round is read before arriving, and only the last thread to arrive moves it on, so no
  // thread can miss the round it waits for.
  const unsigned round = rounds_.load();
  if (arrived_.fetch_add(1) + 1 == size_) {
    arrived_.store(0);  // before the round moves on: no thread arrives at the next one earlier
    // The others are still waiting: what last() writes, they read once the round has moved. If
    // it throws, run() records the error, which moves the round on with failed_ set.
    if (last) last();
    rounds_.fetch_add(1);
    rounds_.notify_all();
  } else {
    wait_until([&] { return rounds_.load() != round || failed_.load(); });
    for (unsigned now = rounds_.load(); now == round && !failed_.load(); now = rounds_.load())
      rounds_.wait(now);
  }
  if (failed_.load()) throw Abandoned{};
}

void ThreadTeam::run(const std::function<void(int)>& job) {
  ++runs_;
  if (size_ == 1) {
    job(0);
    return;
  }
  job_ = &job;
  error_ = nullptr;
  arrived_.store(0);
  failed_.store(false);
  busy_.store(size_ - 1);
  generation_.fetch_add(1);  // publishes job_ to the workers
  generation_.notify_all();
  job_of(0);
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
    job_of(t);
    if (busy_.fetch_sub(1) == 1) busy_.notify_one();
  }
}

void Barrier::wait(const std::function<void()>& last) const {
  if (!team_) {
    if (last) last();
    return;
  }
  if (!waited_) {
    team_->sync(last);
    return;
  }
  const auto start = std::chrono::steady_clock::now();
  team_->sync(last);
  *waited_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::vector<Index> even_bounds(Index n, int parts) {
  std::vector<Index> bounds(static_cast<size_t>(parts) + 1);
  for (int t = 0; t <= parts; ++t)
    bounds[static_cast<size_t>(t)] = n * t / parts;
  return bounds;
}

bool balance_bounds(std::vector<Index>& bounds, const std::vector<double>& work, Index align,
                    Index max_shift, double tolerance) {
  const size_t parts = work.size();
  if (parts < 2 || bounds.size() != parts + 1) return false;
  double total = 0.0, busiest = 0.0;
  for (const double w : work) {
    if (!(w >= 0.0) || !std::isfinite(w)) return false;  // a clock that went wrong: no guess
    total += w;
    busiest = std::max(busiest, w);
  }
  if (!(total > 0.0) || busiest <= (1.0 + tolerance) * total / static_cast<double>(parts))
    return false;
  // The measured cost as a function of the item: piece t's work spread evenly over its items
  // (the pieces as they were measured). Bound k should sit where that cost reaches k / parts of
  // the total.
  const std::vector<Index> measured = bounds;
  const auto where = [&](double cost) {
    double before = 0.0;
    for (size_t t = 0; t < parts; ++t) {
      const Index length = measured[t + 1] - measured[t];
      if (cost <= before + work[t] && work[t] > 0.0)
        return static_cast<double>(measured[t]) +
               (cost - before) / work[t] * static_cast<double>(length);
      before += work[t];
    }
    return static_cast<double>(measured.back());
  };
  const Index n = bounds.back();
  bool moved = false;
  for (size_t k = 1; k < parts; ++k) {
    const double goal = where(total * static_cast<double>(k) / static_cast<double>(parts));
    const double half = std::clamp(0.5 * (goal - static_cast<double>(bounds[k])),
                                   -static_cast<double>(max_shift), static_cast<double>(max_shift));
    Index next = static_cast<Index>(std::llround((static_cast<double>(bounds[k]) + half) /
                                                 static_cast<double>(align))) *
                 align;
    next = std::clamp(next, bounds[k - 1], n);
    if (next == bounds[k]) continue;
    bounds[k] = next;
    moved = true;
  }
  return moved;
}

void for_ranges_with_barrier(
    ThreadTeam* team, const std::vector<Index>& bounds,
    const std::function<void(Index begin, Index end, const Barrier& barrier)>& range,
    ThreadProfile* profile, std::vector<double>* work) {
  const int parts = team ? team->size() : 1;
  const auto piece = [&](int t, ThreadTeam* meet, double* waited) {
    if (parts == 1) {
      range(bounds.front(), bounds.back(), Barrier(nullptr, waited));
    } else {
      range(bounds[static_cast<size_t>(t)], bounds[static_cast<size_t>(t) + 1],
            Barrier(meet, waited));
    }
  };
  if (!profile && !work) {
    if (parts == 1) {
      piece(0, nullptr, nullptr);
    } else {
      team->run([&](int t) { piece(t, team, nullptr); });
    }
    return;
  }
  using Clock = std::chrono::steady_clock;
  const auto since = [](Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
  };
  std::vector<double> own;
  std::vector<double>& times = work ? *work : own;  // waits first, then the work
  times.assign(static_cast<size_t>(parts), 0.0);
  const Clock::time_point start = Clock::now();
  const auto timed_piece = [&](int t) {
    const Clock::time_point begun = Clock::now();
    double& waited = times[static_cast<size_t>(t)];
    piece(t, parts == 1 ? nullptr : team, &waited);
    waited = since(begun) - waited;
  };
  if (parts == 1) {
    timed_piece(0);
  } else {
    team->run(timed_piece);
  }
  if (!profile) return;
  profile->wall += since(start);
  ++profile->jobs;
  double busiest = 0.0, sum = 0.0;
  for (const double w : times) {
    busiest = std::max(busiest, w);
    sum += w;
  }
  profile->busiest += busiest;
  profile->busy += sum / parts;
}

}  // namespace clothlab
