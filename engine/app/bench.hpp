// bench.hpp: `clothlab bench`, measurements that print figures and ratios from one run.
#pragma once

#include <filesystem>
#include <functional>
#include <string_view>

#include <CLI/CLI.hpp>

namespace clothlab::app {
void add_bench_command(CLI::App& app);
void add_bench_speed_command(CLI::App& bench);    // bench_speed.cpp
void add_bench_methods_command(CLI::App& bench);  // bench_methods.cpp

// Runs `python3 script csv plot` (the plot scripts the bench commands write next to their CSV)
// and, when the plot could not be drawn, warns how to get it.
void draw_plot(const std::filesystem::path& script, const std::filesystem::path& csv,
               const std::filesystem::path& plot);

// Runs a bench command's body: a bad scene is reported as `clothlab run` reports it (exit 2),
// another error as "error: bench NAME: ..." (exit 1).
void run_bench_command(std::string_view name, const std::function<int()>& body);
}  // namespace clothlab::app
