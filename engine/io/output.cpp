#include "io/output.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "clothlab/core/guard.hpp"
#include "io/run_folder.hpp"

#include "clothlab/forces/spring_damper.hpp"

namespace clothlab {

namespace {

// The first line of each file, as FrameWriter writes it and `repair` reads it.
constexpr std::string_view kEnergyHeader = "frame,t,kinetic,potential,total,px,py,pz";
constexpr std::string_view kPositionsHeader = "frame,t,particle,x,y,z";
constexpr std::string_view kVelocitiesHeader = "frame,t,particle,vx,vy,vz";
constexpr std::string_view kSpringsHeader = "frame,t,effect,spring,i,j,strain,tension";

std::string with_newline(std::string_view text) {
  return std::string(text) + "\n";
}

}  // namespace

FrameWriter::FrameWriter(const Folder& dir, bool velocities, bool springs, bool npy,
                         Index particles, bool page)
    : page_(page) {
  files_ = {dir.path() / "energy.csv"};
  energy_ = AppendFile(dir, "energy.csv");
  energy_.append(with_newline(kEnergyHeader));
  if (npy) {
    files_.push_back(dir.path() / "positions.npy");
    positions_npy_.emplace(dir, "positions.npy", particles);
  } else {
    files_.push_back(dir.path() / "positions.csv");
    positions_ = AppendFile(dir, "positions.csv");
    positions_.append(with_newline(kPositionsHeader));
  }
  if (velocities && npy) {
    files_.push_back(dir.path() / "velocities.npy");
    velocities_npy_.emplace(dir, "velocities.npy", particles);
  } else if (velocities) {
    files_.push_back(dir.path() / "velocities.csv");
    velocities_ = AppendFile(dir, "velocities.csv");
    velocities_.append(with_newline(kVelocitiesHeader));
  }
  if (springs) {
    files_.push_back(dir.path() / "springs.csv");
    springs_ = AppendFile(dir, "springs.csv");
    springs_.append(with_newline(kSpringsHeader));
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

// What `repair` reads of a CSV file of frames: where each frame's rows end, and how many frames
// it holds whole.
struct CsvFrames {
  off_t header_end = 0;          // the size of the file with its header alone
  std::vector<off_t> frame_end;  // frame_end[f]: with the rows of frames 0 to f
  long whole = 0;                // frames held whole
  // The size that holds the header and the rows of the first `frames` frames (no more than it
  // has), and no cut line.
  off_t size_for(long frames) const {
    return frames == 0 ? header_end : frame_end[static_cast<size_t>(frames - 1)];
  }
};

// Reads the CSV file `fd` (`path`) of frames: its first line must be `header`, each whole row after
// it a row of the frame it is in or of the next, from frame 0 on (with `one_row`, one row a frame,
// as energy.csv). A line without its '\n' at the end is a cut line, which is not read.
// The rows of a whole frame end in the same row as the frame before it, the row named by the
// fields `key` (a particle: particles 0 to N - 1; a spring's effect, i and j: the springs in
// their order, less those torn since), so a last frame that ends in another row is cut short (a
// torn last spring makes it look so: a whole frame cut, never a cut frame kept); a first frame
// has none before it and is taken whole. Throws OutputError for a file it cannot read so.
CsvFrames read_csv_frames(int fd, const std::filesystem::path& path, std::string_view header,
                          const std::vector<size_t>& key, bool one_row) {
  const auto unreadable = [&](const std::string& why) {
    return OutputError(
        fmt::format("{} is not a file of frames as clothlab writes it: {}; repair cut nothing",
                    path.string(), why));
  };
  constexpr size_t kLongestLine = 4096;  // clothlab's rows are a few hundred bytes at most
  constexpr size_t kBlock = 1 << 20;
  std::string block(kBlock, '\0');
  CsvFrames frames;
  std::string line, row_key, last_key, previous_key;
  bool header_read = false, too_long = false;
  long line_number = 0;
  off_t at = 0;
  for (;;) {
    const ssize_t got = ::pread(fd, block.data(), block.size(), at);
    if (got < 0) throw unreadable(system_reason(errno));
    if (got == 0) break;
    for (ssize_t k = 0; k < got; ++k) {
      const char c = block[static_cast<size_t>(k)];
      if (c != '\n') {
        if (line.size() < kLongestLine) {
          line += c;
        } else {
          too_long = true;
        }
        continue;
      }
      ++line_number;
      const off_t end = at + k + 1;
      if (too_long) throw unreadable(fmt::format("line {} is too long for a row", line_number));
      if (!header_read) {
        if (line != header) {
          throw unreadable(fmt::format("its first line is not the header \"{}\"", header));
        }
        header_read = true;
        frames.header_end = end;
        line.clear();
        continue;
      }
      // The fields: the frame, t, then the key's.
      std::vector<std::string_view> fields;
      for (size_t from = 0;;) {
        const size_t comma = line.find(',', from);
        fields.emplace_back(std::string_view(line).substr(from, comma - from));
        if (comma == std::string::npos) break;
        from = comma + 1;
      }
      long frame = -1;
      const std::string_view first = fields.front();
      const auto [rest, error] = std::from_chars(first.data(), first.data() + first.size(), frame);
      const long current = static_cast<long>(frames.frame_end.size()) - 1;
      if (error != std::errc() || rest != first.data() + first.size() ||
          std::any_of(key.begin(), key.end(), [&](size_t f) { return f >= fields.size(); })) {
        throw unreadable(fmt::format("line {} is not a row of a frame", line_number));
      }
      if (frame != current + 1 && (one_row || frame != current || current < 0)) {
        throw unreadable(
            fmt::format("line {} is a row of frame {} after {}", line_number, frame,
                        current < 0 ? "the header" : fmt::format("frame {}", current)));
      }
      row_key.clear();
      for (const size_t f : key)
        row_key.append(fields[f]).append(",");
      if (frame != current) {
        previous_key = std::exchange(last_key, row_key);
        frames.frame_end.push_back(end);
      } else {
        last_key = row_key;
        frames.frame_end.back() = end;
      }
      line.clear();
    }
    at += got;
  }
  if (!header_read) throw unreadable("it holds no whole header line");
  const long held = static_cast<long>(frames.frame_end.size());
  frames.whole = one_row || held <= 1 || last_key == previous_key ? held : held - 1;
  return frames;
}

// What `repair` reads of a .npy file of frames: its particles, and the frames it holds whole.
struct NpyFrames {
  long particles = 0;
  long count = 0;  // frames its header counts
  long whole = 0;  // frames it holds whole
};

NpyFrames read_npy_frames(int fd, const std::filesystem::path& path) {
  const auto unreadable = [&](const std::string& why) {
    return OutputError(
        fmt::format("{} is not a file of frames as clothlab writes it: {}; repair cut nothing",
                    path.string(), why));
  };
  std::string head(NpyFrameWriter::kHeaderBytes, '\0');
  struct stat status {};
  if (::fstat(fd, &status) != 0) throw unreadable(system_reason(errno));
  if (::pread(fd, head.data(), head.size(), 0) != NpyFrameWriter::kHeaderBytes) {
    throw unreadable("it is shorter than its header");
  }
  long count = 0, particles = 0;
  const size_t shape = head.find("'shape': (");
  // The header as NpyFrameWriter::header writes it, but for the numbers.
  if (shape == std::string::npos ||
      std::sscanf(head.c_str() + shape, "'shape': (%ld, %ld, 3)", &count, &particles) != 2 ||
      count < 0 || particles < 1 || head != NpyFrameWriter::header(count, particles)) {
    throw unreadable("its header is not that of 32-bit floats of shape (frames, particles, 3)");
  }
  const off_t frame_bytes = static_cast<off_t>(particles) * 3 * 4;
  const off_t data = status.st_size - NpyFrameWriter::kHeaderBytes;
  // The header counts a frame once its bytes are in (io/npy.hpp); a file cut shorter holds less.
  return {particles, count, std::min(count, static_cast<long>(data / frame_bytes))};
}

}  // namespace

long cut_to_common_frames(const std::filesystem::path& dir) {
  const Folder folder(dir, /*no_link=*/true);
  // Only a run's folder, and not while a run writes there.
  const PageFolderLock lock = lock_run_folder(folder);
  struct Descriptors {
    std::vector<int> fds;
    ~Descriptors() {
      for (const int fd : fds)
        ::close(fd);
    }
  } opened;
  const auto open = [&](const char* name) -> int {
    const int fd = ::openat(folder.fd(), name, O_RDWR | O_NOFOLLOW | O_CLOEXEC);
    if (fd < 0 && errno != ENOENT) {
      throw OutputError(fmt::format("cannot open {}: {}; repair cut nothing", (dir / name).string(),
                                    system_reason(errno)));
    }
    if (fd >= 0) opened.fds.push_back(fd);
    return fd;
  };
  // Every file is read before any is cut: a file repair cannot read leaves them all as they are.
  const int energy = open("energy.csv");
  if (energy < 0) {
    throw OutputError(fmt::format("{} holds no energy.csv; repair cut nothing", dir.string()));
  }
  const CsvFrames energy_frames =
      read_csv_frames(energy, dir / "energy.csv", kEnergyHeader, {}, /*one_row=*/true);
  long frames = energy_frames.whole;
  struct Csv {
    const char* name;
    std::string_view header;
    std::vector<size_t> key;  // the fields that name a row: the particle; a spring's effect, i, j
    int fd = -1;
    CsvFrames read;
  };
  Csv csvs[] = {{"positions.csv", kPositionsHeader, {2}, -1, {}},
                {"velocities.csv", kVelocitiesHeader, {2}, -1, {}},
                {"springs.csv", kSpringsHeader, {2, 4, 5}, -1, {}}};
  for (Csv& csv : csvs) {
    csv.fd = open(csv.name);
    if (csv.fd < 0) continue;
    csv.read = read_csv_frames(csv.fd, dir / csv.name, csv.header, csv.key, false);
    frames = std::min(frames, csv.read.whole);
  }
  struct Npy {
    const char* name;
    int fd = -1;
    NpyFrames read;
  };
  Npy npys[] = {{"positions.npy", -1, {}}, {"velocities.npy", -1, {}}};
  for (Npy& npy : npys) {
    npy.fd = open(npy.name);
    if (npy.fd < 0) continue;
    npy.read = read_npy_frames(npy.fd, dir / npy.name);
    frames = std::min(frames, npy.read.whole);
  }
  if (npys[0].fd >= 0 && npys[1].fd >= 0 && npys[0].read.particles != npys[1].read.particles) {
    throw OutputError(fmt::format(
        "{} holds frames of {} particles and {} of {}: they are not one run's files; repair cut "
        "nothing",
        (dir / npys[0].name).string(), npys[0].read.particles, (dir / npys[1].name).string(),
        npys[1].read.particles));
  }

  const auto cut = [&](int fd, off_t size, const char* name) {
    struct stat status {};
    if (::fstat(fd, &status) == 0 && status.st_size > size && ::ftruncate(fd, size) != 0) {
      throw OutputError(
          fmt::format("cannot cut {} back: {}", (dir / name).string(), system_reason(errno)));
    }
  };
  // energy.csv first, as a run writes it last: if repair itself is stopped, its rows are still
  // frames every other file holds.
  cut(energy, energy_frames.size_for(frames), "energy.csv");
  for (const Csv& csv : csvs) {
    if (csv.fd >= 0) cut(csv.fd, csv.read.size_for(frames), csv.name);
  }
  for (const Npy& npy : npys) {
    if (npy.fd < 0) continue;
    const std::string header = NpyFrameWriter::header(frames, npy.read.particles);
    if (npy.read.count != frames &&
        ::pwrite(npy.fd, header.data(), header.size(), 0) != static_cast<ssize_t>(header.size())) {
      throw OutputError(
          fmt::format("cannot write {}: {}", (dir / npy.name).string(), system_reason(errno)));
    }
    cut(npy.fd,
        NpyFrameWriter::kHeaderBytes + static_cast<off_t>(frames) * npy.read.particles * 3 * 4,
        npy.name);
  }
  return frames;
}

}  // namespace clothlab
