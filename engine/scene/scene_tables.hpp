// scene_tables.hpp: the tables a scene file may hold, and the function that reads each.
#pragma once

#include <functional>
#include <span>
#include <string>
#include <string_view>

#include "scene/scene.hpp"
#include "scene/scene_reader.hpp"

namespace clothlab {

struct SceneTableKind {
  std::string_view name;     // as written in the file: "gravity" for [gravity]
  bool repeated;             // true: [[name]], one table per item (e.g. one per particle)
  bool required;             // a scene without it is an error
  std::string_view keys;     // every key the table may hold, separated by spaces
  std::string_view summary;  // what the table holds, quoted when it is missing
  void (*read)(SceneTable& table, Scene& scene);
  // The keys whose numbers a running program may change while the motion goes on (a live
  // page's sliders): the physics, not the geometry, the step or the output. Recorded in
  // Scene::tunables with the values the reader accepts.
  std::string_view tunable = "";
};

// Every table, in the order they are read: parts first, then effects, then run settings.
std::span<const SceneTableKind> scene_table_kinds();
const SceneTableKind* find_scene_table(std::string_view name);
std::string scene_table_names();  // "title particle gravity ...": every top-level name

// After every table is read: checks that need the whole scene ("at least one particle"),
// calling fail(message), and builds what several tables feed (the "springs" effect).
void finish_scene(Scene& scene, const std::function<void(const std::string&)>& fail);

}  // namespace clothlab
