#include "io/mesh_export.hpp"

#include <iterator>
#include <stdexcept>

#include <fmt/format.h>

#include "clothlab/bodies/normals.hpp"
#include "clothlab/forces/spring_damper.hpp"
#include "io/files.hpp"

namespace clothlab {

namespace {

// Every spring of the world's spring effects, as (i, j, l0).
struct SpringView {
  Index i, j;
  double l0;
};
std::vector<SpringView> all_springs(const World& world) {
  std::vector<SpringView> springs;
  for (const auto& effect : world.force_effects) {
    if (const auto* s = dynamic_cast<const SpringDampers*>(effect.get())) {
      const SpringSet& set = s->springs();
      for (size_t k = 0; k < set.size(); ++k)
        springs.push_back({set.i(k), set.j(k), set.l0(k)});
    }
  }
  return springs;
}

}  // namespace

MeshExporter::MeshExporter(const Folder& parent, const std::string& name, bool obj, bool vtk)
    : obj_(obj), vtk_(vtk) {
  if (obj_ || vtk_) dir_.emplace(parent, name);
}

void MeshExporter::write(const World& world, long frame) {
  const Matrix3X& x = world.particles.x;
  const std::string stem = fmt::format("frame_{:04}", frame);
  const std::vector<SpringView> springs = all_springs(world);
  if (obj_) {
    fmt::memory_buffer text;
    const auto out = std::back_inserter(text);
    fmt::format_to(out, "# clothlab frame {} at t = {} s\n", frame, world.t);
    for (Index i = 0; i < x.cols(); ++i) {
      fmt::format_to(out, "v {} {} {}\n", x(0, i), x(1, i), x(2, i));
    }
    if (!world.triangles.empty()) {
      const Matrix3X n = vertex_normals(x, world.triangles);
      for (Index i = 0; i < n.cols(); ++i) {
        fmt::format_to(out, "vn {} {} {}\n", n(0, i), n(1, i), n(2, i));
      }
      // OBJ counts from 1; "a//a" gives vertex a its own normal a.
      for (const Triangle& t : world.triangles) {
        fmt::format_to(out, "f {0}//{0} {1}//{1} {2}//{2}\n", t[0] + 1, t[1] + 1, t[2] + 1);
      }
    } else {
      for (const SpringView& s : springs)
        fmt::format_to(out, "l {} {}\n", s.i + 1, s.j + 1);
    }
    write_whole_file(*dir_, stem + ".obj", std::string_view(text.data(), text.size()));
  }
  if (vtk_) {
    const std::string name = stem + ".vtk";
    fmt::memory_buffer text;
    const auto out = std::back_inserter(text);
    const Matrix3X& v = world.particles.v;
    fmt::format_to(out, "# vtk DataFile Version 3.0\nclothlab frame {} t = {}\n", frame, world.t);
    fmt::format_to(out, "ASCII\nDATASET POLYDATA\nPOINTS {} double\n", x.cols());
    for (Index i = 0; i < x.cols(); ++i)
      fmt::format_to(out, "{} {} {}\n", x(0, i), x(1, i), x(2, i));
    // Cells in VTK's order, lines (the springs) before polygons (the triangles).
    fmt::format_to(out, "LINES {} {}\n", springs.size(), 3 * springs.size());
    for (const SpringView& s : springs)
      fmt::format_to(out, "2 {} {}\n", s.i, s.j);
    fmt::format_to(out, "POLYGONS {} {}\n", world.triangles.size(), 4 * world.triangles.size());
    for (const Triangle& t : world.triangles)
      fmt::format_to(out, "3 {} {} {}\n", t[0], t[1], t[2]);
    // Strain of each spring, l / l0 - 1 (0 at rest, 0.1 = stretched by 10 %); triangles get 0.
    fmt::format_to(out, "CELL_DATA {}\nSCALARS strain double 1\nLOOKUP_TABLE default\n",
                   springs.size() + world.triangles.size());
    for (const SpringView& s : springs) {
      const double l = (x.col(s.j) - x.col(s.i)).norm();
      fmt::format_to(out, "{}\n", s.l0 > 0.0 ? l / s.l0 - 1.0 : 0.0);
    }
    for (size_t k = 0; k < world.triangles.size(); ++k)
      fmt::format_to(out, "0\n");
    fmt::format_to(out, "POINT_DATA {}\nVECTORS velocity double\n", x.cols());
    for (Index i = 0; i < v.cols(); ++i)
      fmt::format_to(out, "{} {} {}\n", v(0, i), v(1, i), v(2, i));
    write_whole_file(*dir_, name, std::string_view(text.data(), text.size()));
    vtk_files_.emplace_back(name, world.t);
    finish();  // the index names every whole frame at every moment
  }
}

void MeshExporter::finish() const {
  if (!vtk_) return;
  std::string text = "{\n  \"file-series-version\": \"1.0\",\n  \"files\": [\n";
  for (size_t k = 0; k < vtk_files_.size(); ++k) {
    fmt::format_to(std::back_inserter(text), "    {{\"name\": \"{}\", \"time\": {}}}{}\n",
                   vtk_files_[k].first, vtk_files_[k].second, k + 1 < vtk_files_.size() ? "," : "");
  }
  text += "  ]\n}\n";
  write_whole_file(*dir_, "frames.vtk.series", text);
}

}  // namespace clothlab
