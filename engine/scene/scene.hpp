// scene.hpp: a scene file, read into a world ready to step.
//
// A scene is a TOML file. Each table names one effect or part ([gravity], [integrator], ...);
// a table that is present is simulated, one that is absent is never constructed. Anything the
// reader does not understand is an error of the form
//   FILE:LINE:COL: what is wrong; what was expected
// raised before anything is simulated or written. An input that runs but is likely a mistake (a
// particle pinned twice, fps above the step rate, ...) is a warning of the same form instead,
// kept in Scene::warnings for the caller to print.
#pragma once

#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "clothlab/after_step/moving_pins.hpp"
#include "clothlab/bodies/cloth.hpp"
#include "clothlab/bodies/rope.hpp"
#include "clothlab/bodies/solid.hpp"
#include "clothlab/core/world.hpp"
#include "clothlab/forces/spring_damper.hpp"

namespace clothlab {

class SceneError : public std::runtime_error {
 public:
  SceneError(const std::string& source, long line, long column, const std::string& message);
  const std::string& source() const { return source_; }
  long line() const { return line_; }
  long column() const { return column_; }
  const std::string& message() const { return message_; }

 private:
  std::string source_;
  long line_;
  long column_;
  std::string message_;
};

// Something odd about a scene that still runs: where it is, what is odd and what to do.
struct SceneWarning {
  std::string source;
  long line = 1;
  long column = 1;
  std::string message;       // "what is odd; what to do"
  std::string text() const;  // "FILE:LINE:COL: message"
};

// A number of the scene that a running program may change while the motion goes on (a live
// page's slider): the tables declare which of their keys are such (SceneTableKind::tunable), and
// the reader records each as it reads it, with the values it accepts.
struct TunableNumber {
  std::string path;  // where it is: "springs.ks", "aerodynamics.wind[2]", "plane[1].e"
  double value = 0.0;
  double min = 0.0, max = 0.0;  // the values the reader accepts (may be infinite)
  bool min_exclusive = false;   // true: value must be > min
  std::string unit;
  bool in_text = true;  // false: the reader's default, the key absent from the text
};

struct OutputSettings {
  double fps = 30.0;        // frames written per simulated second [1/s]
  bool velocities = false;  // also velocities.csv: each particle's velocity, every frame
  bool springs = false;     // also springs.csv: each spring's strain and tension, every frame
  bool npy = false;  // format = "npy": positions.npy (and velocities.npy) in place of the CSV
};

struct Scene {
  std::string source;  // the file name errors and reports use
  std::string title;   // optional `title = "..."` at the top of the file
  World world;
  double dt = 0.0;        // time step [s]
  double duration = 0.0;  // simulated time [s]
  OutputSettings output;
  std::vector<SceneWarning> warnings;   // inputs that run but are likely mistakes, as found
  std::vector<TunableNumber> tunables;  // what a running program may change, in reading order

  // What the builders made, for the tables read after them (springs, bending, aerodynamics).
  std::optional<ClothGrid> cloth;
  std::optional<Rope> rope;
  std::optional<SolidLattice> solid;
  std::vector<PinPath> pin_paths;  // the bodies' moving pins: the "moving_pins" effect

  // The first start, if any, at a position or a velocity past what a 32-bit float holds
  // (3.4e38), which the guard's bounds let through when they are widened: where it is in the
  // file and what is wrong. The CSV files keep doubles, but the page and the .npy files keep
  // floats, so run_scene refuses such a start before it writes anything when it would write one
  // of those; `clothlab validate` warns of it.
  std::optional<SceneWarning> position_beyond_float, velocity_beyond_float;

  long step_count() const;  // steps needed to cover `duration`
};

// The largest scene file read [bytes].
inline constexpr size_t kMaxSceneBytes = size_t{16} << 20;

// Reads the scene file at `path`: a regular file of at most kMaxSceneBytes. Throws SceneError.
Scene load_scene_file(const std::filesystem::path& path);

// Reads a scene from `text`; `source` names it in errors (a path, or e.g. "<demo>").
Scene parse_scene(std::string_view text, const std::string& source);

}  // namespace clothlab
