// viewer.hpp: a run as one self-contained HTML file that plays it back in any browser.
//
// The recorder keeps a copy of the positions of the recorded frames (as 32-bit floats: plenty
// for the eye, half the size), with the time and the energies, and writes them into the page
// template viewer.html. The page needs no network and no install: double-click it.
//
// A page holds at most `max_frames` frames and at most `budget` bytes of them, whichever is
// fewer, and always the first and the last frame of the run: a run that offers more keeps every
// k-th, plus the last. A frame of N particles takes 12 N bytes (a 1000 x 1000 cloth: 12 MB), so
// a big cloth is sampled more thinly than a small one; sampling_note() says how. When one frame
// alone is over the budget, the page still holds two, the first and the last.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "clothlab/core/world.hpp"
#include "io/files.hpp"

namespace clothlab {

class ViewerRecorder {
 public:
  // 256 MiB of frames by default. The page carries them as base64 text, 4/3 as long: 341 MiB
  // (358 million characters), read by the page's script as one string. The longest string some
  // browsers' script engines make is 2^29 - 24 (about 537 million) characters, so this leaves
  // room for the mesh of a 1000 x 1000 cloth (about 100 million characters) and a browser opens
  // the page; a tab then holds the text and the decoded frames, about 1 GB.
  static constexpr long kDefaultBudget = 256L << 20;  // [bytes]

  // `expected_frames` is how many frames the run will offer (an estimate: a run that offers
  // more is sampled more thinly as it goes, by doubling the stride); the page keeps at most
  // `max_frames` of them and at most `budget` bytes [bytes] of positions.
  ViewerRecorder(std::string title, std::string source, long expected_frames, long max_frames = 600,
                 long budget = kDefaultBudget);

  // Offers the world's current state as the next frame.
  void offer(const World& world);

  // Writes the page. Call it at the end of a run, or when the run stopped early. The page is
  // written to a temporary file beside `html` and renamed over it when whole, so that `html` is
  // at every moment the old page or the new one, whole. Throws std::runtime_error naming `html`
  // and the system's reason when it cannot; the temporary file is then removed.
  void write(const World& world, const std::filesystem::path& html) const;
  // The same for the page `name` in `folder` (a run's folder, held open: io/files.hpp).
  void write(const World& world, const Folder& folder, const std::string& name) const;

  // Says on the page that the guard stopped the run (a SimulationError): its message, the step
  // and the particle it names (-1: none), shown over the cloth, and the page's last frame marked
  // as the last before the stop. Call it before the last write.
  void stopped(std::string message, long step, Index particle);

  long frames_offered() const { return offered_; }
  long frames_kept() const;  // the frames the page holds, the last one included

  // Empty when the page holds every frame offered; otherwise what it holds and why, e.g. "the
  // page keeps every 12th frame and the last (51 of 601): a page holds at most 256 MiB of
  // frames, 12 MiB each". The caller may add where every frame is ("; positions.csv has all").
  std::string sampling_note() const;

 private:
  struct Frame {
    std::vector<float> x;                            // positions, 3 floats a particle [m]
    double t = 0.0, kinetic = 0.0, potential = 0.0;  // [s], [J], [J]
  };

  // Keeps every other kept frame and doubles the stride: a run longer than expected.
  void thin_out();

  std::string title_;
  std::string source_;
  long expected_frames_;
  long max_frames_;
  long budget_;              // [bytes]
  long limit_ = 0;           // frames a page holds, the last one included; set by the first offer
  long stride_ = 0;          // keep every stride-th frame offered; set by the first offer
  long offered_ = 0;         // frames offered so far
  std::vector<Frame> kept_;  // offered frames 0, stride, 2 stride, ...
  Frame last_;               // the latest frame offered, when it is not in kept_
  bool last_pending_ = false;
  // The cloth's surface as it was from a kept frame on: a tear (lesson 06) changes it mid-run.
  std::vector<std::pair<long, std::vector<Triangle>>> surfaces_;
  std::vector<Triangle> last_surface_;  // last_'s surface, when it differs from the kept ones
  bool last_surface_differs_ = false;
  struct Stop {
    std::string message;
    long step = 0;
    Index particle = -1;
  };
  std::optional<Stop> stop_;  // the guard's, when it stopped the run
};

}  // namespace clothlab
