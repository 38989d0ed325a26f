// local_global.cpp: the local/global solver's iterations in the engine room
// (FastEngine::local_global_iterate; the lecture's loop is LocalGlobal::advance, lesson 13).
//
// Each iteration is three passes and a solve:
//   1. the local step, spring by spring, on the positions in the fast layout (all x, then all y,
//      then all z), through the exercise's local_step_projection, into d in the same layout:
//      each spring writes only its own d, so the springs are split over the threads and, with
//      the kernel inlined (link-time optimisation), several are taken at once;
//   2. the right-hand side, row by row: each unknown adds the pushes h^2 ks d of its springs in
//      the order of the spring list, as the lecture's loop adds them, so it gets the same bits
//      on any number of threads, with no two threads writing one row;
//   3. the global step's solve, the three coordinates at once (one N x 3 right-hand side) with
//      CHOLMOD's simplicial Cholesky factor in an AMD ordering, factored once per matrix;
//   4. the solution to the particles, row by row, split over the threads.
// Steps 1, 2 and 4 give the lecture's bits; the solve is another factorisation of the same
// matrix, so the positions agree within rounding (the bound tests/fast/ derives). SPEED.md has
// the choices measured (orderings, supernodal or simplicial, Eigen or CHOLMOD).
#include <Eigen/CholmodSupport>
#include <stdexcept>
#include <vector>

#include "clothlab/core/stop.hpp"
#include "clothlab/core/world.hpp"
#include "clothlab/integrators/local_global.hpp"
#include "fast/engine.hpp"
#include "fast/incidence.hpp"
#include "fast/vectorise.hpp"

namespace clothlab::fast {

struct LocalGlobalRoom {
  const LocalGlobalSystem* system = nullptr;  // the system factored, at its version
  long version = -1;
  Index rows = -1;
  Eigen::CholmodSimplicialLLT<Eigen::SparseMatrix<double>> llt;
  // Each unknown's springs, in the order of the list: entry 2 s for a spring whose end i it is,
  // 2 s + 1 for end j; the row r's run from start[r] to start[r + 1].
  std::vector<Index> start, incident;
  SoA3Matrix x;           // [m] the positions in the fast layout
  std::vector<double> d;  // [m] every spring's d: all x, then all y, then all z
  Eigen::Matrix<double, Eigen::Dynamic, 3> b, solution;
};

namespace {

// The local step on springs [begin, end): d from the positions x (component c of particle i at
// x[c nx + i]), d's component c of spring s at d[c ns + s]. Each spring writes its own d.
[[gnu::noinline, gnu::flatten]] void local_steps(size_t begin, size_t end,
                                                 const Index* __restrict si,
                                                 const Index* __restrict sj,
                                                 const double* __restrict l0,
                                                 const double* __restrict x, Index nx,
                                                 double* __restrict d, size_t ns) {
  CLOTHLAB_INDEPENDENT_ITERATIONS
  for (size_t s = begin; s < end; ++s) {
    const Index i = si[s], j = sj[s];
    const Vec3 e = local_step_projection(Vec3(x[i], x[nx + i], x[2 * nx + i]),
                                         Vec3(x[j], x[nx + j], x[2 * nx + j]), l0[s],
                                         Vec3(d[s], d[ns + s], d[2 * ns + s]));
    d[s] = e.x();
    d[ns + s] = e.y();
    d[2 * ns + s] = e.z();
  }
  CLOTHLAB_INDEPENDENT_ITERATIONS_END
}

// Rows [begin, end) of the right-hand side: b_fixed plus each of the row's springs' pushes, in
// the spring list's order, + for its end i and - for its end j (the lecture's loop's order).
void right_hand_side(Index begin, Index end, const LocalGlobalRoom& room,
                     const LocalGlobalSystem& system, Eigen::Matrix<double, Eigen::Dynamic, 3>& b) {
  const size_t ns = system.push.size();
  const Index rows = b.rows();
  const double* fixed = system.b_fixed.data();
  double* out = b.data();
  for (int c = 0; c < 3; ++c) {
    const double* dc = room.d.data() + c * ns;
    for (Index r = begin; r < end; ++r) {
      double sum = fixed[c * rows + r];
      for (Index k = room.start[static_cast<size_t>(r)]; k < room.start[static_cast<size_t>(r) + 1];
           ++k) {
        const Index e = room.incident[static_cast<size_t>(k)];
        const auto s = static_cast<size_t>(e >> 1);
        const double push = system.push[s] * dc[s];
        sum = (e & 1) ? sum - push : sum + push;
      }
      out[c * rows + r] = sum;
    }
  }
}

// Factors the system's matrix and lists each unknown's springs, when the system is new.
void prepare_room(LocalGlobalRoom& room, const LocalGlobalSystem& system) {
  const Index rows = system.a.rows();
  if (room.system == &system && room.version == system.version && room.rows == rows) return;
  auto& options = room.llt.cholmod();
  options.nmethods = 1;  // AMD alone: CHOLMOD's default also tries METIS, slower to order
  options.method[0].ordering = CHOLMOD_AMD;
  room.llt.compute(system.a);
  if (room.llt.info() != Eigen::Success)
    throw std::runtime_error("local-global: CHOLMOD could not factor M + h C + h^2 L");
  group_ends_by_row(
      system.i, system.j, rows,
      [&](Index particle) { return system.unknown[static_cast<size_t>(particle)]; }, room.start,
      room.incident);
  room.system = &system;
  room.version = system.version;
  room.rows = rows;
}

}  // namespace

bool FastEngine::local_global_iterate(World& world, LocalGlobalSystem& system, int iterations) {
  if (!local_global_) local_global_ = std::make_shared<LocalGlobalRoom>();
  LocalGlobalRoom& room = *local_global_;
  prepare_room(room, system);
  Particles& p = world.particles;
  const Index n = p.size(), rows = system.a.rows();
  const size_t ns = system.i.size();
  room.x.resize(3, padded_columns<double>(n, 21));
  const Index nx = room.x.cols();
  world.for_particles(
      [&](Index begin, Index end) { to_soa(begin, end, p.x.data(), room.x.data(), nx); });
  room.d.resize(3 * ns);
  for (size_t s = 0; s < ns; ++s) {
    for (int c = 0; c < 3; ++c)
      room.d[c * ns + s] = system.d(c, static_cast<Index>(s));
  }
  room.b.resize(rows, 3);
  for (int it = 0; it < iterations; ++it) {
    stop_point();
    world.for_items(static_cast<Index>(ns), [&](Index begin, Index end) {
      local_steps(static_cast<size_t>(begin), static_cast<size_t>(end), system.i.data(),
                  system.j.data(), system.l0.data(), room.x.data(), nx, room.d.data(), ns);
    });
    world.for_items(
        rows, [&](Index begin, Index end) { right_hand_side(begin, end, room, system, room.b); });
    room.solution = room.llt.solve(room.b);
    world.for_items(rows, [&](Index begin, Index end) {
      for (int c = 0; c < 3; ++c) {
        for (Index r = begin; r < end; ++r)
          room.x(c, system.particle[static_cast<size_t>(r)]) = room.solution(r, c);
      }
    });
  }
  world.for_particles(
      [&](Index begin, Index end) { from_soa(begin, end, room.x.data(), nx, p.x.data()); });
  for (size_t s = 0; s < ns; ++s) {
    for (int c = 0; c < 3; ++c)
      system.d(c, static_cast<Index>(s)) = room.d[c * ns + s];
  }
  return true;
}

}  // namespace clothlab::fast
