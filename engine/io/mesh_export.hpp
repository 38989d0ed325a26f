// mesh_export.hpp: frames as standard mesh files, for Blender and ParaView.
//
//   OBJ sequence   frame_0001.obj, frame_0002.obj, ...: vertices, per-vertex normals and the
//                  cloth's triangles (or the springs as lines when there are no triangles).
//                  Blender imports a sequence with a mesh-sequence add-on; any viewer opens one.
//   VTK series     frame_0001.vtk, ... (legacy VTK polydata) with per-vertex velocity and
//                  per-spring strain (l / l0 - 1), indexed by frames.vtk.series with the time of
//                  each file, which ParaView opens as one animated data set.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "clothlab/core/world.hpp"
#include "io/files.hpp"

namespace clothlab {

class MeshExporter {
 public:
  // Writes the formats asked for into the folder `name` in `parent` (made if needed, and never
  // a symbolic link: io/files.hpp).
  MeshExporter(const Folder& parent, const std::string& name, bool obj, bool vtk);

  // Writes the world's current state as frame number `frame` (numbered from 1 in file names).
  void write(const World& world, long frame);

  // Writes the VTK series index (write() keeps it up to date after each frame).
  void finish() const;

 private:
  std::optional<Folder> dir_;  // only when a format is asked for
  bool obj_, vtk_;
  std::vector<std::pair<std::string, double>> vtk_files_;  // name and time [s]
};

}  // namespace clothlab
