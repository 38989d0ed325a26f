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

// Where a bench command writes, checked before it measures anything, so that it never replaces a
// user's file by surprise (as `clothlab run` never writes into a user's folder without --force).
// Each throws OutputError naming the path and saying what to do, unless `force`:
//   check_bench_file    `file`, given as `option` ("--csv"), must be absent or a regular file
//                       whose first line is `header`, the bench's own CSV header;
//   check_bench_folder  `dir`, given as --out, must not be a symbolic link, and be absent, empty,
//                       or a folder a bench wrote: one holding `csv` (checked as above);
//   check_bench_plot    `plot` must be absent, or a regular file beside the bench's own `csv`
//                       (a plot has nothing of its own to tell it from a user's).
// A folder, device or other file that is not a regular one is refused even with `force`.
void check_bench_file(const std::filesystem::path& file, std::string_view option,
                      std::string_view header, bool force);
void check_bench_folder(const std::filesystem::path& dir, const std::string& csv,
                        std::string_view header, bool force);
void check_bench_plot(const std::filesystem::path& plot, const std::string& csv,
                      std::string_view header, bool force);
// The option `--force` of the bench commands that write files.
void add_bench_force_option(CLI::App& command, bool& force);

// Runs a bench command's body: a bad scene is reported as `clothlab run` reports it (exit 2),
// another error as "error: bench NAME: ..." (exit 1), running out of memory as well (with a
// word on what to ask for instead).
void run_bench_command(std::string_view name, const std::function<int()>& body);
}  // namespace clothlab::app
