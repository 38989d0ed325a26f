// bench.hpp: `clothlab bench`, measurements that print figures and ratios from one run.
#pragma once

#include <CLI/CLI.hpp>

namespace clothlab::app {
void add_bench_command(CLI::App& app);
void add_bench_speed_command(CLI::App& bench);  // bench_speed.cpp
}  // namespace clothlab::app
