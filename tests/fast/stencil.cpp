// Grid stencils (engine/fast/springs.hpp): the fast path takes a grid's rows of springs as
// stencils that hold their rest lengths as a few distinct rows; the layout describes exactly the
// springs of the set, the engine really takes it, a spring that tears or yields leaves it, and
// the states stay the readable path's, bit for bit, on any number of threads and any block size.
#include <doctest/doctest.h>

#include <string>
#include <utility>
#include <vector>

#include "clothlab/forces/spring_damper.hpp"
#include "fast/engine.hpp"
#include "fast/springs.hpp"
#include "fast_util.hpp"
#include "scene/scene.hpp"

using clothlab::Index;
using clothlab::same_bits;
using test::engine_of;
using test::identical;

namespace {

// The hanging cloth of rows x cols in a wind, and `extra`. Its rest lengths round to several
// values along a row and down a column.
std::string grid(Index rows, Index cols, const std::string& extra = "",
                 const std::string& wind = "[3, 0, 2]") {
  return test::hanging_cloth(rows, cols) + R"(
[aerodynamics]
wind = )" +
         wind +
         R"(
[integrator]
method = "symplectic-euler"
dt = 0.0005
duration = 1.0
)" + extra;
}

// The scene after `steps` steps, on the fast path or the readable one, with `threads` threads
// and, on the fast path, blocks of `block` particles.
clothlab::Scene run(const std::string& text, bool fast, int threads, int steps,
                    Index block = clothlab::fast::kPassBlock) {
  return test::run(text, fast, threads, steps, [&](clothlab::World& world) {
    if (fast) engine_of(world).pass_block = block;
  });
}

clothlab::SpringSet& set_of(clothlab::World& world, const char* name) {
  clothlab::SpringDampers* effect = clothlab::find_spring_effect(world, name);
  REQUIRE(effect != nullptr);
  return effect->springs();
}
const clothlab::SpringSet& set_of(const clothlab::World& world, const char* name) {
  const clothlab::SpringDampers* effect = clothlab::find_spring_effect(world, name);
  REQUIRE(effect != nullptr);
  return effect->springs();
}

// Whether the layout, read back spring by spring in its order (runs and stencils), gives the
// set's springs in the set's order: the same ends, and for a stencil's springs the same ks, kd
// and rest length, bit for bit.
bool describes(const clothlab::fast::SpringLayout& layout, const clothlab::SpringSet& s) {
  size_t k = 0;
  bool same = true;
  const auto run = [&](const clothlab::fast::SpringRun& r) {
    same = same && r.k0 == k;
    for (Index t = 0; t < r.length; ++t, ++k) {
      same = same && k < s.size() && s.i(k) == r.i0 + t && s.j(k) == r.j0 + t &&
             (!r.uniform || (same_bits(s.ks(k), s.ks(r.k0)) && same_bits(s.kd(k), s.kd(r.k0))));
    }
  };
  size_t next = 0;
  for (const clothlab::fast::SpringStencil& st : layout.stencils) {
    for (; next < st.runs_before; ++next)
      run(layout.runs[next]);
    same = same && st.k0 == k && st.row_l0.size() == static_cast<size_t>(st.rows) &&
           st.l0.size() <= clothlab::fast::kStencilRestRows * static_cast<size_t>(st.length);
    for (Index r = 0; r < st.rows; ++r) {
      for (Index c = 0; c < st.length; ++c, ++k) {
        const Index shift = r * st.stride + c;
        const size_t rest = st.row_l0[static_cast<size_t>(r)] + static_cast<size_t>(c);
        same = same && k < s.size() && s.i(k) == st.i0 + shift && s.j(k) == st.j0 + shift &&
               same_bits(s.ks(k), st.ks) && same_bits(s.kd(k), st.kd) && rest < st.l0.size() &&
               same_bits(s.l0(k), st.l0[rest]);
      }
    }
  }
  for (; next < layout.runs.size(); ++next)
    run(layout.runs[next]);
  return same && k == s.size();
}

clothlab::fast::SpringLayout layout_of(const clothlab::SpringSet& s) {
  return clothlab::fast::spring_layout(s, clothlab::fast::spring_runs(s));
}

}  // namespace

TEST_CASE("fast stencil: a grid's springs all go into stencils that describe them exactly") {
  // bench speed's cloth (128 x 128, 1 cm apart) and smaller ones, odd and even: every family
  // (rows, columns, both diagonals, row and column bending) is a stencil, though the rest
  // lengths round to several values (9 along a row of bench speed's cloth).
  for (const auto& [rows, cols] : {std::pair<Index, Index>{128, 128}, {23, 19}, {5, 40}}) {
    CAPTURE(rows);
    CAPTURE(cols);
    std::string text = grid(rows, cols);
    text.replace(text.find("spacing = 0.02"), 14, "spacing = 0.01");
    clothlab::Scene scene = clothlab::parse_scene(text, "stencil.toml");
    for (const char* name : {"springs", "bending"}) {
      CAPTURE(name);
      const clothlab::SpringSet& s = set_of(scene.world, name);
      const clothlab::fast::SpringLayout layout = layout_of(s);
      CHECK(layout.runs.empty());
      CHECK(layout.stencil_springs() == s.size());
      CHECK(describes(layout, s));
      // On bench speed's cloth, rows of rest lengths that differ: the stencils hold them as a
      // few distinct rows, not as one number.
      size_t distinct_rows = 0;
      for (const clothlab::fast::SpringStencil& st : layout.stencils)
        distinct_rows += st.l0.size() / static_cast<size_t>(st.length);
      if (rows == 128) CHECK(distinct_rows > layout.stencils.size());
    }
  }
}

TEST_CASE(
    "fast stencil: the engine takes a grid through stencils, and a torn or yielded row "
    "leaves them") {
  const Index rows = 23, cols = 19;
  clothlab::Scene scene = run(grid(rows, cols), true, 1, 1);
  clothlab::SpringSet& springs = set_of(scene.world, "springs");
  clothlab::SpringSet& bending = set_of(scene.world, "bending");
  const size_t all = springs.size() + bending.size();
  REQUIRE(engine_of(scene.world).plan().find("springs+ bending+") != std::string::npos);
  CHECK(engine_of(scene.world).stencil_springs() == all);
  // A rest length set to its own bits (plasticity's elastic springs, every step) is no change;
  // other bits are.
  const unsigned long rest = springs.rest_version(), version = springs.version();
  springs.set_l0(3, springs.l0(3));
  CHECK(springs.rest_version() == rest);
  // A row spring (the set starts with the row springs, row by row) yields in row 4: that row,
  // and only that one, leaves its stencil.
  const size_t yielded = 4 * static_cast<size_t>(cols - 1) + 7;
  springs.set_l0(yielded, 1.05 * springs.l0(yielded));
  CHECK(springs.rest_version() != rest);
  CHECK(springs.version() == version);
  scene.world.step(scene.dt);
  CHECK(engine_of(scene.world).stencil_springs() == all - static_cast<size_t>(cols - 1));
  CHECK(describes(layout_of(springs), springs));
  // A column spring too (the columns follow the rows: rows - 1 rows of cols springs): its row.
  const size_t column = static_cast<size_t>(rows * (cols - 1) + 5 * cols + 2);
  REQUIRE(springs.j(column) - springs.i(column) == cols);
  springs.set_l0(column, 0.97 * springs.l0(column));
  scene.world.step(scene.dt);
  CHECK(engine_of(scene.world).stencil_springs() == all - static_cast<size_t>(2 * cols - 1));
  // The first spring of row 9 tears: the rest of the row is a shorter run, out of the stencil.
  const size_t torn = 9 * static_cast<size_t>(cols - 1);
  springs.erase({torn});
  scene.world.step(scene.dt);
  CHECK(engine_of(scene.world).stencil_springs() == all - static_cast<size_t>(3 * cols - 2));
  CHECK(describes(layout_of(springs), springs));
  // The yielded spring back at its built length, bit for bit: its row may join again.
  springs.set_l0(yielded, springs.l_built(yielded));
  scene.world.step(scene.dt);
  CHECK(engine_of(scene.world).stencil_springs() == all - static_cast<size_t>(2 * cols - 1));
}

TEST_CASE(
    "fast stencil: grids give the readable state bit for bit on 1-4 threads and odd "
    "blocks") {
  const std::string text = grid(23, 19);
  const clothlab::Scene readable = run(text, false, 1, 200);
  for (int threads : {1, 2, 3, 4}) {
    for (const Index block : {Index{1}, Index{7}, Index{333}, Index{100000}}) {
      CAPTURE(threads);
      CAPTURE(block);
      const clothlab::Scene fast = run(text, true, threads, 200, block);
      REQUIRE(engine_of(fast.world).stencil_springs() > 0);
      CHECK(fast.world.backend_evaluations == fast.world.force_evaluations);
      CHECK(identical(fast.world.particles.x, readable.world.particles.x));
      CHECK(identical(fast.world.particles.v, readable.world.particles.v));
      CHECK(identical(fast.world.particles.f, readable.world.particles.f));
    }
  }
}

TEST_CASE("fast stencil: tearing and plasticity leave the stencils with the readable bits") {
  // A sheet hung by its top edge in a gust, stretched past its yield and tearing limits: rows
  // leave their stencils step by step, while the others stay.
  std::string text = grid(
      24, 21, "[plasticity]\nyield_strain = 0.03\nmax_strain = 0.4\n[tearing]\nstrain = 0.12\n",
      "[0, 0, 12]");
  text.replace(text.find("mass = 0.5"), 10, "mass = 0.1");
  text.replace(text.find("top-corners"), 11, "top-edge");
  const clothlab::Scene readable = run(text, false, 1, 1500);
  const clothlab::Scene first = run(text, true, 1, 1);
  const size_t at_start = engine_of(first.world).stencil_springs();
  for (int threads : {1, 2, 3, 4}) {
    for (const Index block : {Index{7}, Index{100000}}) {
      CAPTURE(threads);
      CAPTURE(block);
      clothlab::Scene fast = run(text, true, threads, 1500, block);
      const clothlab::SpringSet& s = set_of(fast.world, "springs");
      const size_t now = engine_of(fast.world).stencil_springs();
      CHECK(now > 0);
      CHECK(now < at_start);
      CHECK(s.size() < set_of(first.world, "springs").size());
      CHECK(describes(layout_of(s), s));
      CHECK(identical(fast.world.particles.x, readable.world.particles.x));
      CHECK(identical(fast.world.particles.v, readable.world.particles.v));
    }
  }
  // Plastic flow did happen: some rest lengths left their built lengths.
  const clothlab::SpringSet& r = set_of(readable.world, "springs");
  bool yielded = false;
  for (size_t k = 0; k < r.size(); ++k)
    yielded = yielded || !same_bits(r.l0(k), r.l_built(k));
  CHECK(yielded);
}
