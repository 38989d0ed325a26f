// bench.hpp: `clothlab bench`, measurements that print figures and ratios from one run.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include <CLI/CLI.hpp>

namespace clothlab::app {
void add_bench_command(CLI::App& app);
void add_bench_speed_command(CLI::App& bench);     // bench_speed.cpp
void add_bench_methods_command(CLI::App& bench);   // bench_methods.cpp
void add_bench_roofline_command(CLI::App& bench);  // bench_roofline.cpp

// `bench speed`'s N x N cloth (bench_speed.cpp), for `bench roofline`: its scene, on the fast
// path, on `threads` threads; and the engine's step on it, timed as `bench speed` times its
// `reference` row on 1 thread: ns per spring-step, the median of `repeats` repeats of at least
// `min_seconds` each.
std::string speed_cloth_scene(int n, int threads);
double reference_ns_per_spring_step(int n, int repeats, double min_seconds);
// `bench speed`'s `kernel` row, timed the same way: the fast path's spring loop alone over the
// first 256 springs of a row of its 32 x 32 cloth, whose data stay in the first-level cache (no
// copies, no guard, no move); ns per spring.
double kernel_ns_per_spring(int repeats, double min_seconds);
// The option `--sizes N,N,...` of the commands that time bench speed's cloths.
void add_cloth_sizes_option(CLI::App& command, std::vector<int>& sizes);

// What one wake of `threads` threads costs with nothing to do [ns]: ThreadTeam::run of a job
// that only meets `meetings` times at the barrier (ThreadTeam::sync), the fastest of 5 runs of
// `wakes` (bench_methods.cpp, bench_roofline.cpp).
double wake_ns(int threads, int meetings = 0, int wakes = 20000);

// Runs `python3 script csv plot` (the plot scripts the bench commands write next to their CSV)
// and, when the plot could not be drawn, warns how to get it.
void draw_plot(const std::filesystem::path& script, const std::filesystem::path& csv,
               const std::filesystem::path& plot);

// Runs a bench command's body: a bad scene is reported as `clothlab run` reports it (exit 2),
// another error as "error: bench NAME: ..." (exit 1).
void run_bench_command(std::string_view name, const std::function<int()>& body);
}  // namespace clothlab::app
