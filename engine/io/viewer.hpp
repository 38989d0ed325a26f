// viewer.hpp: a run as one self-contained HTML file that plays it back in any browser.
//
// The recorder keeps a copy of the positions of every recorded frame (as 32-bit floats: plenty
// for the eye, half the size), with the time and the energies, and writes them into the page
// template viewer.html. The page needs no network and no install: double-click it.
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "clothlab/core/world.hpp"

namespace clothlab {

class ViewerRecorder {
 public:
  // `expected_frames` is how many frames the run will offer; at most `max_frames` of them are
  // kept (every k-th), so that a long run still makes a page a browser opens quickly.
  ViewerRecorder(std::string title, std::string source, long expected_frames,
                 long max_frames = 600);

  // Offers the world's current state as the next frame.
  void offer(const World& world);

  // Writes the page. Call it at the end of a run, or when the run stopped early.
  void write(const World& world, const std::filesystem::path& html) const;

  long frames_kept() const { return static_cast<long>(times_.size()); }

 private:
  std::string title_;
  std::string source_;
  long stride_ = 1;   // keep every stride-th frame offered
  long offered_ = 0;  // frames offered so far
  std::vector<std::vector<float>> positions_;
  std::vector<double> times_, kinetic_, potential_;
  // The cloth's surface as it was from a frame on: a tear (lesson 06) changes it mid-run.
  std::vector<std::pair<long, std::vector<Triangle>>> surfaces_;
};

}  // namespace clothlab
