#include "io/output.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string_view>

#include <fmt/format.h>

#include "clothlab/core/guard.hpp"

#include "clothlab/forces/spring_damper.hpp"

namespace clothlab {

FrameWriter::FrameWriter(const Folder& dir, bool velocities, bool springs, bool npy,
                         Index particles, bool page)
    : page_(page) {
  files_ = {dir.path() / "energy.csv"};
  energy_ = AppendFile(dir, "energy.csv");
  energy_.append("frame,t,kinetic,potential,total,px,py,pz\n");
  if (npy) {
    files_.push_back(dir.path() / "positions.npy");
    positions_npy_.emplace(dir, "positions.npy", particles);
  } else {
    files_.push_back(dir.path() / "positions.csv");
    positions_ = AppendFile(dir, "positions.csv");
    positions_.append("frame,t,particle,x,y,z\n");
  }
  if (velocities && npy) {
    files_.push_back(dir.path() / "velocities.npy");
    velocities_npy_.emplace(dir, "velocities.npy", particles);
  } else if (velocities) {
    files_.push_back(dir.path() / "velocities.csv");
    velocities_ = AppendFile(dir, "velocities.csv");
    velocities_.append("frame,t,particle,vx,vy,vz\n");
  }
  if (springs) {
    files_.push_back(dir.path() / "springs.csv");
    springs_ = AppendFile(dir, "springs.csv");
    springs_.append("frame,t,effect,spring,i,j,strain,tension\n");
  }
}

namespace {

// Frame `frame` (after step `step`) would write `what` = `value`, which `why` says is wrong.
[[noreturn]] void refuse_frame(const World& world, long frame, long step, std::string_view what,
                               double value, Index particle = -1,
                               std::string_view why =
                                   "a number too large for a double, or not "
                                   "a number") {
  throw SimulationError(fmt::format("frame {} (after step {}, t = {:.6g} s) would write a {} of "
                                    "{}: {}; stopped before writing it (the files hold the "
                                    "frames before it)",
                                    frame, step, world.t, what, value, why),
                        step, particle);
}

// Refuses a frame with a coordinate of `m` that a 32-bit float cannot hold: it would be inf
// in `where` (a .npy file or the page), though a finite double in the CSV files.
void check_float_range(const World& world, long frame, long step, const Matrix3X& m,
                       std::string_view what, std::string_view where) {
  constexpr double kFloatMax = std::numeric_limits<float>::max();  // 3.4e38
  for (Index i = 0; i < m.cols(); ++i) {
    if (m.col(i).cwiseAbs().maxCoeff() > kFloatMax) {
      refuse_frame(
          world, frame, step, what, m.col(i).cwiseAbs().maxCoeff(), i,
          fmt::format("more than a 32-bit float holds ({:.3g}), which {} keeps", kFloatMax, where));
    }
  }
}

// One row per particle of the columns of m: "frame,t,particle,x,y,z".
std::string particle_rows(const Matrix3X& m, long frame, double t) {
  std::string rows;
  for (Index i = 0; i < m.cols(); ++i) {
    fmt::format_to(std::back_inserter(rows), "{},{:.17g},{},{:.17g},{:.17g},{:.17g}\n", frame, t, i,
                   m(0, i), m(1, i), m(2, i));
  }
  return rows;
}

// One row per spring of every spring effect: strain (l - l0) / l0 and tension f_sd, the
// spring-damper's force on end i along e = (x_j - x_i) / l (lesson 02): positive pulls the ends
// together.
std::string spring_rows(const World& world, long frame, long step) {
  const Particles& p = world.particles;
  std::string rows;
  for (const auto& effect : world.force_effects) {
    const auto* family = dynamic_cast<const SpringDampers*>(effect.get());
    if (!family) continue;
    const SpringSet& s = family->springs();
    for (size_t k = 0; k < s.size(); ++k) {
      const Vec3 e_star = p.x.col(s.j(k)) - p.x.col(s.i(k));
      const double l = e_star.norm();
      const Vec3 f1 = spring_damper_force(p.x.col(s.i(k)), p.x.col(s.j(k)), p.v.col(s.i(k)),
                                          p.v.col(s.j(k)), s.ks(k), s.kd(k), s.l0(k));
      // + 0.0: a spring at rest, f_sd = -0, prints as 0.
      const double tension = (l > 0.0 ? f1.dot(e_star) / l : 0.0) + 0.0;
      const double strain = s.l0(k) > 0.0 ? (l - s.l0(k)) / s.l0(k) : 0.0;
      if (!std::isfinite(tension)) refuse_frame(world, frame, step, "spring tension [N]", tension);
      if (!std::isfinite(strain)) refuse_frame(world, frame, step, "spring strain", strain);
      fmt::format_to(std::back_inserter(rows), "{},{:.17g},{},{},{},{},{},{:.17g}\n", frame,
                     world.t, family->name(), k, s.i(k), s.j(k),
                     s.l0(k) > 0.0 ? fmt::format("{:.17g}", strain) : std::string(), tension);
    }
  }
  return rows;
}

// Throws SimulationError unless every value a frame would write is finite: with the guard's
// bounds wide enough, 1/2 m v^2 or a spring's energy can overflow to inf though x and v did not.
void check_finite_frame(const World& world, long frame, long step, double kinetic, double potential,
                        const Vec3& p) {
  const auto refuse = [&](std::string_view what, double value, Index particle) {
    refuse_frame(world, frame, step, what, value, particle);
  };
  if (!std::isfinite(world.t)) refuse("time", world.t, -1);
  if (!std::isfinite(kinetic)) refuse("kinetic energy [J]", kinetic, -1);
  if (!std::isfinite(potential)) refuse("potential energy [J]", potential, -1);
  if (!std::isfinite(kinetic + potential)) refuse("total energy [J]", kinetic + potential, -1);
  if (!p.allFinite()) refuse("momentum [kg m/s]", p.norm(), -1);
  const Particles& particles = world.particles;
  for (Index i = 0; i < particles.size(); ++i) {
    if (!particles.x.col(i).allFinite()) refuse("position [m]", particles.x.col(i).norm(), i);
    if (!particles.v.col(i).allFinite()) refuse("velocity [m/s]", particles.v.col(i).norm(), i);
  }
}

}  // namespace

void FrameWriter::write(const World& world, long frame, long step) {
  // {:.17g} prints a double so that it reads back bit for bit.
  const double kinetic = world.kinetic_energy();
  const double potential = world.potential_energy();
  const Vec3 p = world.momentum();
  check_finite_frame(world, frame, step, kinetic, potential, p);
  if (positions_npy_) {
    check_float_range(world, frame, step, world.particles.x, "position [m]", "positions.npy");
  } else if (page_) {
    check_float_range(world, frame, step, world.particles.x, "position [m]", "the page");
  }
  if (velocities_npy_) {
    check_float_range(world, frame, step, world.particles.v, "velocity [m/s]", "velocities.npy");
  }
  std::string springs;
  if (springs_.is_open()) springs = spring_rows(world, frame, step);

  // The frame goes to every file or to none: a file that cannot take it takes it back from
  // those that did.
  AppendFile* const files[] = {&positions_, &velocities_, &springs_, &energy_};
  off_t sizes[std::size(files)];
  for (size_t k = 0; k < std::size(files); ++k)
    sizes[k] = files[k]->size();
  const long npy_frames = positions_npy_ ? positions_npy_->frames() : 0;
  try {
    if (positions_npy_) positions_npy_->append(world.particles.x);
    if (velocities_npy_) velocities_npy_->append(world.particles.v);
    if (positions_.is_open()) positions_.append(particle_rows(world.particles.x, frame, world.t));
    if (velocities_.is_open()) velocities_.append(particle_rows(world.particles.v, frame, world.t));
    if (springs_.is_open()) springs_.append(springs);
    energy_.append(fmt::format("{},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g}\n",
                               frame, world.t, kinetic, potential, kinetic + potential, p.x(),
                               p.y(), p.z()));
  } catch (const OutputError&) {
    for (size_t k = 0; k < std::size(files); ++k)
      files[k]->cut_back(sizes[k]);
    if (positions_npy_) positions_npy_->cut_back(npy_frames);
    if (velocities_npy_) velocities_npy_->cut_back(npy_frames);
    throw;
  }
}

namespace {

// The size to cut the CSV file `fd` back to so that it holds its header and its rows of frames
// below `frames`, and no cut line: the rows are in frame order, the frame their first field.
off_t csv_size_for(int fd, long frames) {
  constexpr size_t kBlock = 1 << 20;
  std::string block(kBlock, '\0');
  off_t at = 0, line_start = 0;
  std::string first_field;  // of the line being read
  bool in_first_field = true, header = true;
  for (;;) {
    const ssize_t got = ::pread(fd, block.data(), block.size(), at);
    if (got <= 0) return line_start;  // the end: a line without its '\n' is cut off
    for (ssize_t k = 0; k < got; ++k) {
      const char c = block[static_cast<size_t>(k)];
      if (c == '\n') {
        const off_t next = at + k + 1;
        if (!header) {
          char* end = nullptr;
          const long frame = std::strtol(first_field.c_str(), &end, 10);
          if (first_field.empty() || *end != '\0' || frame >= frames) return line_start;
        }
        header = false;
        line_start = next;
        first_field.clear();
        in_first_field = true;
      } else if (in_first_field) {
        if (c == ',') {
          in_first_field = false;
        } else {
          first_field += c;
        }
      }
    }
    at += got;
  }
}

}  // namespace

long cut_to_common_frames(const std::filesystem::path& dir) {
  const Folder folder(dir, /*no_link=*/true);
  const auto open = [&](const char* name) {
    const int fd = ::openat(folder.fd(), name, O_RDWR | O_NOFOLLOW | O_CLOEXEC);
    if (fd < 0 && errno != ENOENT) {
      throw OutputError(
          fmt::format("cannot open {}: {}", (dir / name).string(), system_reason(errno)));
    }
    return fd;
  };
  const auto cut = [&](int fd, off_t size, const char* name) {
    struct stat status {};
    if (::fstat(fd, &status) == 0 && status.st_size > size && ::ftruncate(fd, size) != 0) {
      const int error = errno;
      ::close(fd);
      throw OutputError(
          fmt::format("cannot cut {} back: {}", (dir / name).string(), system_reason(error)));
    }
    ::close(fd);
  };
  // energy.csv takes each frame last (FrameWriter::write): its whole rows are the frames that
  // every other file holds.
  const int energy = open("energy.csv");
  if (energy < 0) throw OutputError(fmt::format("{} holds no energy.csv", dir.string()));
  const off_t energy_size = csv_size_for(energy, std::numeric_limits<long>::max());
  long frames = 0;
  {
    std::string text(static_cast<size_t>(energy_size), '\0');
    if (::pread(energy, text.data(), text.size(), 0) != static_cast<ssize_t>(text.size())) {
      ::close(energy);
      throw OutputError(fmt::format("cannot read {}", (dir / "energy.csv").string()));
    }
    frames = std::count(text.begin(), text.end(), '\n') - 1;  // the rows below the header
  }
  frames = std::max(frames, 0L);
  cut(energy, energy_size, "energy.csv");
  for (const char* name : {"positions.csv", "velocities.csv", "springs.csv"}) {
    if (const int fd = open(name); fd >= 0) cut(fd, csv_size_for(fd, frames), name);
  }
  for (const char* name : {"positions.npy", "velocities.npy"}) {
    const int fd = open(name);
    if (fd < 0) continue;
    std::string head(NpyFrameWriter::kHeaderBytes, '\0');
    const bool read = ::pread(fd, head.data(), head.size(), 0) == NpyFrameWriter::kHeaderBytes;
    long held = 0, particles = 0;
    const size_t shape = head.find("'shape': (");
    if (!read || shape == std::string::npos ||
        std::sscanf(head.c_str() + shape, "'shape': (%ld, %ld, 3)", &held, &particles) != 2) {
      ::close(fd);
      throw OutputError(
          fmt::format("{} is not a file of frames clothlab wrote", (dir / name).string()));
    }
    const long keep = std::min(held, frames);
    const std::string header = NpyFrameWriter::header(keep, particles);
    if (::pwrite(fd, header.data(), header.size(), 0) != static_cast<ssize_t>(header.size())) {
      ::close(fd);
      throw OutputError(fmt::format("cannot write {}", (dir / name).string()));
    }
    cut(fd, NpyFrameWriter::kHeaderBytes + static_cast<off_t>(keep) * particles * 3 * 4, name);
  }
  return frames;
}

}  // namespace clothlab
