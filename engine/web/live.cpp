// live.cpp: the engine as the live lesson pages see it, compiled to WebAssembly.
//
// The page drives one Simulation (scene/simulation.hpp, lesson 11) through these few C
// functions: it loads a scene from TOML text, advances it by the frame times of the browser,
// reads the positions and the energies straight out of the module's memory, and pins, drags and
// frees particles with the mouse. A slider is a number in the scene's TOML: the page changes the
// text and calls clothlab_reload(), which reads the scene again and carries the motion over (the
// particles' positions and velocities, the time), so the change takes effect while it runs.
//
// Every function returns a status and leaves a message in clothlab_message() when it fails: the
// scene reader's FILE:LINE:COL errors, the guard's blow-up report, an exercise that is still a
// stub (NotImplemented names the exercise and the lesson).
#include <emscripten/emscripten.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <toml++/toml.h>
#include <nlohmann/json.hpp>

#include "clothlab/after_step/ground_collision.hpp"
#include "clothlab/after_step/tearing.hpp"
#include "clothlab/core/guard.hpp"
#include "clothlab/core/not_implemented.hpp"
#include "clothlab/forces/spring_damper.hpp"
#include "clothlab/integrators/methods.hpp"
#include "scene/scene.hpp"
#include "scene/simulation.hpp"

namespace {

using clothlab::Index;
using clothlab::Simulation;

std::unique_ptr<Simulation> g_simulation;
std::string g_message;         // what the last call that failed said
std::string g_parameters;      // JSON: the numbers of the scene a slider may change
std::vector<int> g_triangles;  // the surface as 32-bit indices, for WebGL
std::vector<int> g_springs;    // spring ends, for drawing the springs
std::vector<double> g_shown;   // positions to draw, 3 per particle
std::vector<unsigned char> g_pinned_by_scene;

enum Status : int { kOk = 0, kBadScene = 1, kBlewUp = 2, kNotDone = 3, kFailed = 4 };

// Runs `work`, turning an exception into a status and a message.
template <typename Work>
int guarded(Work&& work) {
  try {
    work();
    return kOk;
  } catch (const clothlab::SceneError& error) {
    g_message = error.what();
    return kBadScene;
  } catch (const clothlab::SimulationError& error) {
    g_message = error.what();
    return kBlewUp;
  } catch (const clothlab::NotImplemented& error) {
    g_message = error.what();
    return kNotDone;
  } catch (const std::exception& error) {
    g_message = error.what();
    return kFailed;
  }
}

// The numbers of the scene a page may turn into sliders: those the scene reader declares
// tunable (Scene::tunables), each with the values it accepts (a bound that is infinite is null).
void describe(const clothlab::Scene& scene) {
  nlohmann::json numbers = nlohmann::json::array();
  const auto bound = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nullptr; };
  for (const clothlab::TunableNumber& t : scene.tunables) {
    numbers.push_back({{"name", t.path},
                       {"value", t.value},
                       {"min", bound(t.min)},
                       {"max", bound(t.max)},
                       {"min_exclusive", t.min_exclusive},
                       {"unit", t.unit},
                       {"in_text", t.in_text}});
  }
  g_parameters = numbers.dump();
}

// The byte offset in `text` of a toml++ position (line and column from 1, the column counted
// in characters).
size_t offset_of(const std::string& text, const toml::source_position& at) {
  size_t offset = 0;
  for (toml::source_index line = 1; line < at.line && offset < text.size(); ++line) {
    const size_t end = text.find('\n', offset);
    offset = end == std::string::npos ? text.size() : end + 1;
  }
  for (toml::source_index column = 1; column < at.column && offset < text.size(); ++column) {
    ++offset;
    while (offset < text.size() && (static_cast<unsigned char>(text[offset]) & 0xC0) == 0x80)
      ++offset;  // the rest of a character of several bytes
  }
  return offset;
}

// `text` with the value at `path` ("springs.ks", "aerodynamics.wind[0]") replaced by
// `value` (TOML text); a key its table lacks is added under the table's header, a table the
// scene lacks at the end.
std::string edited(const std::string& text, const std::string& path, const std::string& value) {
  const toml::table root = toml::parse(text);
  if (const toml::node* node = root.at_path(path).node()) {
    const size_t begin = offset_of(text, node->source().begin);
    const size_t end = offset_of(text, node->source().end);
    return text.substr(0, begin) + value + text.substr(end);
  }
  const size_t dot = path.rfind('.');
  if (dot == std::string::npos || path.find('[') != std::string::npos) {
    throw std::invalid_argument(fmt::format("the scene has no {} to change", path));
  }
  const std::string table = path.substr(0, dot), key = path.substr(dot + 1);
  if (const toml::table* t = root.at_path(table).as_table(); t && !t->is_inline()) {
    const size_t header = offset_of(text, t->source().begin);
    const size_t line_end = text.find('\n', header);
    const size_t at = line_end == std::string::npos ? text.size() : line_end + 1;
    const std::string before = line_end == std::string::npos ? "\n" : "";
    return text.substr(0, at) + before + key + " = " + value + "\n" + text.substr(at);
  }
  return text + (text.empty() || text.back() == '\n' ? "" : "\n") + "\n[" + table + "]\n" + key +
         " = " + value + "\n";
}

// The surface and the springs as 32-bit indices, for drawing.
void take_surface() {
  const clothlab::World& world = g_simulation->world();
  g_triangles.clear();
  for (const clothlab::Triangle& t : world.triangles)
    g_triangles.insert(g_triangles.end(), t.begin(), t.end());
  g_springs.clear();
  for (const auto& effect : world.force_effects) {
    if (const auto* family = dynamic_cast<const clothlab::SpringDampers*>(effect.get())) {
      if (family->name() != "springs") continue;  // bending springs are not drawn
      const clothlab::SpringSet& set = family->springs();
      for (size_t k = 0; k < set.size(); ++k) {
        g_springs.push_back(static_cast<int>(set.i(k)));
        g_springs.push_back(static_cast<int>(set.j(k)));
      }
    }
  }
}

// A spring known by its two ends, the smaller first: what stays the same when a scene is read
// again, whatever order its springs are built in.
using Ends = std::pair<Index, Index>;
using RestLengths = std::map<Ends, double>;

Ends ends_of(const clothlab::SpringSet& s, size_t k) {
  return {std::min(s.i(k), s.j(k)), std::max(s.i(k), s.j(k))};
}

// The rest length of each spring of the family `name` ("springs" or "bending"), or nothing when
// the world has no such family.
std::optional<RestLengths> rest_lengths(const clothlab::World& world, std::string_view name) {
  const clothlab::SpringDampers* family = clothlab::find_spring_effect(world, name);
  if (!family) return std::nullopt;
  RestLengths lengths;
  const clothlab::SpringSet& s = family->springs();
  for (size_t k = 0; k < s.size(); ++k)
    lengths[ends_of(s, k)] = s.l0(k);
  return lengths;
}

// What a running cloth has become that its scene does not say (lesson 06): the rest lengths its
// springs have yielded to, and the springs it has torn. A scene read again for a slider starts
// from its text, so this gives them back: each spring of `family` keeps the rest length it had
// in `before`, and a spring `before` no longer had is torn again (with its triangles and the
// bending springs across it, as the tearing effect does), or simply dropped without one.
void carry_springs(clothlab::World& world, std::string_view family,
                   const std::optional<RestLengths>& before) {
  clothlab::SpringDampers* effect = clothlab::find_spring_effect(world, family);
  if (!effect || !before) return;
  clothlab::SpringSet& s = effect->springs();
  std::vector<size_t> lost;
  for (size_t k = 0; k < s.size(); ++k) {
    const auto it = before->find(ends_of(s, k));
    if (it == before->end()) {
      lost.push_back(k);
    } else {
      s.set_l0(k, it->second);
    }
  }
  if (lost.empty()) return;
  clothlab::Tearing* tearing = nullptr;
  for (const auto& after : world.post_step_effects) {
    if (auto* t = dynamic_cast<clothlab::Tearing*>(after.get())) tearing = t;
  }
  if (tearing && family == "springs") {
    tearing->tear(world, lost);
  } else {
    s.erase(lost);
  }
}

}  // namespace

extern "C" {

// Reads `text` as the scene `name` and starts it from its beginning.
EMSCRIPTEN_KEEPALIVE int clothlab_load(const char* text, const char* name) {
  return guarded([&] {
    clothlab::Scene scene = clothlab::parse_scene(text, name);
    // The page draws the positions as 32-bit floats: a start past a float's range, which a
    // widened [guard] lets through, would be drawn at infinity. Refused at the key that set it,
    // as clothlab run refuses it for a page (io/run.cpp).
    if (const std::optional<clothlab::SceneWarning>& far = scene.position_beyond_float) {
      const std::string& said = far->message;
      throw clothlab::SceneError(
          far->source, far->line, far->column,
          fmt::format("{}; expected |x|, |y|, |z| <= {:.6g} m: the page draws positions as 32-bit "
                      "floats",
                      said.substr(0, said.find("; expected")), std::numeric_limits<float>::max()));
    }
    scene.world.threads = 1;  // one thread in a page
    g_simulation = std::make_unique<Simulation>(std::move(scene));
    const clothlab::Particles& p = g_simulation->world().particles;
    g_pinned_by_scene.assign(static_cast<size_t>(p.size()), 0);
    for (Index i = 0; i < p.size(); ++i)
      g_pinned_by_scene[static_cast<size_t>(i)] = p.inv_m[i] == 0.0;
    take_surface();
    describe(g_simulation->scene());
  });
}

// Reads `text` again and carries the running motion over, when the new scene has as many
// particles: their positions, velocities and time, and what the springs have become (yielded
// rest lengths, torn springs: carry_springs above). The pins of the new scene hold where the
// particles are now.
EMSCRIPTEN_KEEPALIVE int clothlab_reload(const char* text, const char* name) {
  if (!g_simulation) return clothlab_load(text, name);
  const clothlab::World& old = g_simulation->world();
  const clothlab::Matrix3X x = old.particles.x, v = old.particles.v;
  const double t = old.t;
  const std::optional<RestLengths> springs = rest_lengths(old, "springs");
  const std::optional<RestLengths> bending = rest_lengths(old, "bending");
  const int status = clothlab_load(text, name);
  if (status != kOk) return status;
  clothlab::World& world = g_simulation->world();
  if (world.particles.size() != x.cols()) return kOk;  // another cloth: it starts over
  world.particles.x = x;
  world.particles.v = v;
  world.t = t;  // steps stays 0: the guard starts again from the state carried over
  return guarded([&] {
    carry_springs(world, "springs", springs);
    carry_springs(world, "bending", bending);
    take_surface();
  });
}

EMSCRIPTEN_KEEPALIVE const char* clothlab_message() {
  return g_message.c_str();
}

// `text` with one value changed (see edited() above); null, with a message, if it cannot be.
EMSCRIPTEN_KEEPALIVE const char* clothlab_edit(const char* text, const char* path,
                                               const char* value) {
  static std::string result;
  const int status = guarded([&] { result = edited(text, path, value); });
  return status == kOk ? result.c_str() : nullptr;
}

// The integrators a scene may name, as a JSON array.
EMSCRIPTEN_KEEPALIVE const char* clothlab_integrators() {
  static std::string names;
  nlohmann::json list = nlohmann::json::array();
  for (std::string_view name : clothlab::method_names())
    list.push_back(std::string(name));
  names = list.dump();
  return names.c_str();
}
EMSCRIPTEN_KEEPALIVE const char* clothlab_parameters() {
  return g_parameters.c_str();
}

// The method the scene's integrator is ("symplectic-euler", "xpbd", ...).
EMSCRIPTEN_KEEPALIVE const char* clothlab_method() {
  static std::string method;
  method = g_simulation ? std::string(g_simulation->world().integrator->name()) : "";
  return method.c_str();
}

// The solids the cloth meets, as the engine has them, for drawing: a JSON object with "ground"
// (its height, or null), "planes" ([{point, normal}]) and "spheres" ([{centre, radius}]).
EMSCRIPTEN_KEEPALIVE const char* clothlab_colliders() {
  static std::string colliders;
  nlohmann::json out = {{"ground", nullptr},
                        {"planes", nlohmann::json::array()},
                        {"spheres", nlohmann::json::array()}};
  const auto vec = [](const clothlab::Vec3& v) { return nlohmann::json{v.x(), v.y(), v.z()}; };
  if (g_simulation) {
    for (const auto& effect : g_simulation->world().post_step_effects) {
      if (const auto* ground = dynamic_cast<const clothlab::Ground*>(effect.get())) {
        out["ground"] = ground->y0();
      } else if (const auto* plane = dynamic_cast<const clothlab::Plane*>(effect.get())) {
        out["planes"].push_back({{"point", vec(plane->point())}, {"normal", vec(plane->normal())}});
      } else if (const auto* sphere = dynamic_cast<const clothlab::Sphere*>(effect.get())) {
        out["spheres"].push_back({{"centre", vec(sphere->centre())}, {"radius", sphere->radius()}});
      }
    }
  }
  colliders = out.dump();
  return colliders.c_str();
}

// Advances by `frame_time` seconds of simulated time; returns the status (the steps taken are in
// clothlab_steps()).
EMSCRIPTEN_KEEPALIVE int clothlab_advance(double frame_time) {
  if (!g_simulation) return kFailed;
  return guarded([&] {
    g_simulation->advance(frame_time);
    // A tear (lesson 06) changes the surface and the springs.
    const clothlab::World& world = g_simulation->world();
    const clothlab::SpringDampers* springs = clothlab::find_spring_effect(world, "springs");
    if (world.triangles.size() * 3 != g_triangles.size() ||
        (springs && springs->springs().size() * 2 != g_springs.size()))
      take_surface();
  });
}

EMSCRIPTEN_KEEPALIVE double clothlab_time() {
  return g_simulation ? g_simulation->time() : 0.0;
}
EMSCRIPTEN_KEEPALIVE double clothlab_dt() {
  return g_simulation ? g_simulation->dt() : 0.0;
}
EMSCRIPTEN_KEEPALIVE double clothlab_steps() {
  return g_simulation ? static_cast<double>(g_simulation->steps()) : 0.0;
}
EMSCRIPTEN_KEEPALIVE double clothlab_kinetic() {
  return g_simulation ? g_simulation->world().kinetic_energy() : 0.0;
}
EMSCRIPTEN_KEEPALIVE double clothlab_potential() {
  return g_simulation ? g_simulation->world().potential_energy() : 0.0;
}
EMSCRIPTEN_KEEPALIVE int clothlab_particles() {
  return g_simulation ? static_cast<int>(g_simulation->world().particles.size()) : 0;
}

// The positions to draw (between the last two steps, lesson 11), 3 doubles per particle.
EMSCRIPTEN_KEEPALIVE const double* clothlab_positions() {
  const clothlab::Matrix3X& x = g_simulation->interpolated_positions();
  g_shown.assign(x.data(), x.data() + x.size());
  return g_shown.data();
}
// The positions as the last step left them, 3 doubles per particle (what side by side compares:
// a step's change shows in the frame that took it, not a frame later as drawn).
EMSCRIPTEN_KEEPALIVE const double* clothlab_state_positions() {
  return g_simulation->world().particles.x.data();
}
EMSCRIPTEN_KEEPALIVE int clothlab_triangle_count() {
  return static_cast<int>(g_triangles.size() / 3);
}
EMSCRIPTEN_KEEPALIVE const int* clothlab_triangles() {
  return g_triangles.data();
}
EMSCRIPTEN_KEEPALIVE int clothlab_spring_count() {
  return static_cast<int>(g_springs.size() / 2);
}
EMSCRIPTEN_KEEPALIVE const int* clothlab_springs() {
  return g_springs.data();
}

// The strain of the cloth at each particle, for colouring it: of the springs that meet there,
// the one stretched or squeezed most, as l / l0 - 1 (negative when squeezed).
EMSCRIPTEN_KEEPALIVE const double* clothlab_strains() {
  static std::vector<double> strain;
  const clothlab::World& world = g_simulation->world();
  const clothlab::Matrix3X& x = world.particles.x;
  strain.assign(static_cast<size_t>(world.particles.size()), 0.0);
  if (const clothlab::SpringDampers* family = clothlab::find_spring_effect(world, "springs")) {
    const clothlab::SpringSet& s = family->springs();
    for (size_t k = 0; k < s.size(); ++k) {
      if (!(s.l0(k) > 0.0)) continue;  // a spring of no length has no strain to show
      const double e = (x.col(s.j(k)) - x.col(s.i(k))).norm() / s.l0(k) - 1.0;
      for (const Index end : {s.i(k), s.j(k)}) {
        double& at = strain[static_cast<size_t>(end)];
        if (std::abs(e) > std::abs(at)) at = e;
      }
    }
  }
  return strain.data();
}

// Whether particle i is pinned (by the scene, or held by the mouse).
EMSCRIPTEN_KEEPALIVE int clothlab_is_pinned(int i) {
  return g_simulation && g_simulation->world().particles.inv_m[i] == 0.0;
}
EMSCRIPTEN_KEEPALIVE int clothlab_pinned_by_scene(int i) {
  return i >= 0 && static_cast<size_t>(i) < g_pinned_by_scene.size() &&
         g_pinned_by_scene[static_cast<size_t>(i)];
}

// The mouse: hold particle i, move it towards (x, y, z) over the next frame, let it go.
EMSCRIPTEN_KEEPALIVE int clothlab_grab(int i) {
  return guarded([&] { g_simulation->pin(i); });
}
EMSCRIPTEN_KEEPALIVE int clothlab_drag(int i, double x, double y, double z) {
  return guarded([&] { g_simulation->move_pin(i, clothlab::Vec3(x, y, z)); });
}
EMSCRIPTEN_KEEPALIVE int clothlab_release(int i) {
  return guarded([&] {
    if (!clothlab_pinned_by_scene(i)) g_simulation->unpin(i);
  });
}

}  // extern "C"
