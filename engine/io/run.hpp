// run.hpp: runs a scene from start to end, writing its frames.
#pragma once

#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "scene/scene.hpp"

namespace clothlab {

// Where a run writes, and what.
struct RunOutputs {
  std::filesystem::path dir;   // energy.csv and positions.csv go here
  std::filesystem::path html;  // the viewer page (empty: no page)
  bool obj = false;            // an OBJ sequence in dir/frames/
  bool vtk = false;            // a VTK series in dir/frames/
  bool velocities = false;     // velocities.csv, even if the scene's [output] does not ask
  bool springs = false;        // springs.csv, even if the scene's [output] does not ask
  bool npy = false;            // positions.npy in place of positions.csv, as [output] format
  bool force = false;  // write into a folder that is not clothlab's, or over a page that is not
                       // (io/run_folder.hpp)

  // The usual outputs: the CSV files and dir/view.html.
  static RunOutputs in(const std::filesystem::path& dir) { return {dir, dir / "view.html"}; }
};

struct RunReport {
  long steps = 0;             // steps taken
  long frames = 0;            // frames written
  double wall_seconds = 0.0;  // wall-clock time of the stepping loop [s]
  std::string page_note;      // what the page kept of the frames, when not all (empty: all)
  std::vector<std::filesystem::path> files;
};

// Called after each step with (steps done, steps in all); used for a progress bar.
using ProgressFn = std::function<void(long, long)>;

// While alive, SIGINT (Ctrl-C) and SIGTERM ask a run to stop after its current step instead of
// ending the process at once, and the run says so on stderr at once; run_scene then writes that
// step as a last frame and the page, and throws RunStopped. A step that takes long (many
// substeps or iterations, [gravitation]'s pairs) is given up part way instead
// (clothlab/core/stop.hpp): the files keep the frames written before it. A second signal ends
// the process as usual (and may cut the frame being written). SIGXFSZ is ignored meanwhile, so
// that a file past the size limit is an OutputError that names it. A caller that does long work
// before run_scene (the start energy) makes one first, so that a signal then is heard too.
class StopSignals {
 public:
  StopSignals();
  ~StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  static int received();  // the signal that asked for a stop, or 0
};

class RunStopped : public std::runtime_error {
 public:
  // `abandoned`: the step given up part way (0: the first frame's work), or -1 for none.
  RunStopped(int signal, long step, long frames, long abandoned = -1);
  int signal() const { return signal_; }
  long step() const { return step_; }            // the step of the last frame written
  long frames() const { return frames_; }        // frames written
  long abandoned() const { return abandoned_; }  // the step given up part way, or -1

 private:
  int signal_;
  long step_, frames_, abandoned_;
};

// Steps `scene` for its whole duration, writing a frame every 1/fps seconds of simulated time
// (and the first and the last) into the run folder outputs.dir (io/run_folder.hpp), which it
// takes first; the page's place is checked before the first step, too. However the run ends
// (its end, the guard's SimulationError, RunStopped, an OutputError from a full disk), the files
// hold whole frames and the viewer page shows them; the page is also rewritten during a long run
// (every half minute or so), so that it is there after a crash.
// The most steps a run takes at once (World::advance) between two frames, or two looks at the
// stop signals: at most a few milliseconds of steps on the cloths the lessons run.
inline constexpr long kRunStepsAtOnce = 32;

RunReport run_scene(Scene& scene, const RunOutputs& outputs, const ProgressFn& progress = {});

// The same with the usual outputs in `out_dir`.
inline RunReport run_scene(Scene& scene, const std::filesystem::path& out_dir,
                           const ProgressFn& progress = {}) {
  return run_scene(scene, RunOutputs::in(out_dir), progress);
}

}  // namespace clothlab
