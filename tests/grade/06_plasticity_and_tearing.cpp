// Grading tests for lesson 06, plasticity and tearing (exercises ex06.1 and ex06.2).
//
// Every expected value is worked out in the comment beside it, from the lesson's equations;
// none comes from the reference solution. Each case calls its exercise's kernel and checks it
// against a hand-worked number, a limit case or an invariant (an elastic spring comes back
// unchanged, plastic flow never overshoots the current length nor adds energy, the tears chosen
// do not depend on the order the springs are stored in).
#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "clothlab/after_step/plasticity.hpp"
#include "clothlab/after_step/tearing.hpp"
#include "grading.hpp"

using clothlab::Index;
using clothlab::PlasticLimits;

namespace {

using Ends = std::pair<Index, Index>;

// "[a, b, c]": a list of positions, for a failed check.
std::string show(const std::vector<size_t>& v) {
  std::ostringstream out;
  out << "[";
  for (size_t k = 0; k < v.size(); ++k)
    out << (k ? ", " : "") << v[k];
  out << "]";
  return out.str();
}

// "[(a, b), (c, d)]": a list of spring ends, for a failed check.
std::string show(const std::vector<Ends>& v) {
  std::ostringstream out;
  out << "[";
  for (size_t k = 0; k < v.size(); ++k) {
    out << (k ? ", " : "") << "(" << v[k].first << ", " << v[k].second << ")";
  }
  out << "]";
  return out.str();
}

// True when v is strictly increasing: ascending and without duplicates.
bool strictly_ascending(const std::vector<size_t>& v) {
  return std::adjacent_find(v.begin(), v.end(), [](size_t a, size_t b) { return a >= b; }) ==
         v.end();
}

// One spring of a tearing scene: its strain and its end particles (smaller index first).
struct TearSpring {
  double strain;
  Ends ends;
};

}  // namespace

TEST_SUITE("ex06") {
  // --- Exercise ex06.1: the plastic rest length --------------------------------------------------

  TEST_CASE("ex06.1 an elastic spring keeps its rest length exactly" * POINTS(1)) {
    // yield_strain = 0.25 and l0 = 2, all numbers exact in binary. A fast flow (flow_rate dt =
    // 100 * 1 = 100) would move l0 all the way in one step, so any flow at all would show.
    // The spring was built at l_built = l0 = 2 and may change by up to 50 %.
    const PlasticLimits limits{0.25, 100.0, 0.5};
    const double l0 = 2.0;
    // strain = (l - l0) / l0: 2.2 -> +0.1, 1.8 -> -0.1, 2 -> 0, 2.5 -> +0.25, 1.5 -> -0.25.
    // All have |strain| <= 0.25: elastic, l0' = l0 = 2, bit for bit.
    const double stretched = clothlab::plastic_rest_length(2.2, l0, l0, limits, 1.0);
    const double compressed = clothlab::plastic_rest_length(1.8, l0, l0, limits, 1.0);
    const double at_rest = clothlab::plastic_rest_length(2.0, l0, l0, limits, 1.0);
    const double at_yield_stretched = clothlab::plastic_rest_length(2.5, l0, l0, limits, 1.0);
    const double at_yield_compressed = clothlab::plastic_rest_length(1.5, l0, l0, limits, 1.0);
    {
      INFO(
          "an elastic spring must come back unchanged: with |strain| = |l - l0| / l0 = 0.1 "
          "below the yield strain 0.25 (stretched or compressed) return l0 itself, before "
          "computing any target");
      CHECK(stretched == l0);
      CHECK(compressed == l0);
      CHECK(at_rest == l0);
    }
    {
      INFO(
          "at exactly the yield strain (|strain| = 0.25) the spring is still elastic: the test "
          "is |strain| <= yield_strain, and the strain is measured against l0, (l - l0) / l0");
      CHECK(at_yield_stretched == l0);
      CHECK(at_yield_compressed == l0);
    }
    {
      // Just past the yield, l = 2.52: strain 0.26 > 0.25, so it flows, the whole way here:
      // l0' = 2.52 / 1.25 = 2.016.
      const double past_yield = clothlab::plastic_rest_length(2.52, l0, l0, limits, 1.0);
      INFO(
          "just past the yield strain (l = 2.52, strain 0.26) the spring is plastic and takes "
          "the rest length 2.52 / 1.25 = 2.016; got "
          << past_yield);
      CHECK(past_yield == doctest::Approx(2.016).epsilon(1e-12));
    }
  }

  TEST_CASE("ex06.1 past yield a full flow jumps to the yield target" * POINTS(1)) {
    // yield_strain = 0.25, l0 = l_built = 2, max_strain = 0.5: l0 may lie in [1, 3].
    {
      // Stretched to l = 3: strain = 0.5 > 0.25, target = l / (1 + 0.25) = 3 / 1.25 = 2.4
      // (where the strain would be exactly 0.25: 3 / 2.4 - 1 = 0.25). flow_rate dt = 10 * 0.1
      // = 1: the whole way, l0' = 2.4.
      const double r = clothlab::plastic_rest_length(3.0, 2.0, 2.0, {0.25, 10.0, 0.5}, 0.1);
      INFO(
          "a spring stretched to 3 with l0 = 2 and yield strain 0.25 takes the rest length at "
          "which its strain is exactly the yield strain, target = l / (1 + yield_strain) = 2.4, "
          "when flow_rate dt >= 1");
      CHECK(r == doctest::Approx(2.4).epsilon(1e-12));
    }
    {
      // Compressed to l = 1.2: strain = -0.4 < -0.25, target = l / (1 - 0.25) = 1.2 / 0.75 =
      // 1.6. flow_rate dt = 50 * 0.1 = 5 >= 1: the fraction is min(1, 5) = 1, l0' = 1.6.
      const double r = clothlab::plastic_rest_length(1.2, 2.0, 2.0, {0.25, 50.0, 0.5}, 0.1);
      INFO(
          "a compressed spring flows to target = l / (1 - yield_strain) = 1.2 / 0.75 = 1.6, and "
          "flow_rate dt = 5 must not carry it past the target: flow only part of the way, "
          "min(1, flow_rate dt)");
      CHECK(r == doctest::Approx(1.6).epsilon(1e-12));
    }
    {
      // Stretched to l = 3 with flow_rate dt = 40 * 0.5 = 20: still l0' = 2.4, not
      // 2 + 20 (2.4 - 2) = 10.
      const double r = clothlab::plastic_rest_length(3.0, 2.0, 2.0, {0.25, 40.0, 0.5}, 0.5);
      INFO(
          "with flow_rate dt = 20 the rest length must stop at the target 2.4: the fraction of "
          "the way is min(1, flow_rate dt), never more than the whole way");
      CHECK(r == doctest::Approx(2.4).epsilon(1e-12));
    }
    {
      // Stretched to l = 2.6: strain = (2.6 - 2) / 2 = 0.3 > 0.25, plastic. (Measured against l
      // it would be 0.6 / 2.6 = 0.23, elastic.) target = 2.6 / 1.25 = 2.08, full flow.
      const double r = clothlab::plastic_rest_length(2.6, 2.0, 2.0, {0.25, 10.0, 0.5}, 0.1);
      INFO(
          "the strain is measured against the rest length, (l - l0) / l0 = 0.3 here, past the "
          "yield strain 0.25: l0 must flow to 2.6 / 1.25 = 2.08");
      CHECK(r == doctest::Approx(2.08).epsilon(1e-12));
    }
  }

  TEST_CASE("ex06.1 a partial flow covers the fraction flow_rate dt of the way" * POINTS(1)) {
    // yield_strain = 0.25, l0 = l_built = 2, max_strain = 0.5 (l0 may lie in [1, 3]),
    // flow_rate = 10 1/s, dt = 0.03 s: the fraction is flow_rate dt = 0.3.
    const PlasticLimits limits{0.25, 10.0, 0.5};
    {
      // First, as it tells the usual slips apart: flow_rate = 2 1/s, dt = 0.05 s, fraction 0.1,
      // l0' = 2 + 0.1 (2.4 - 2) = 2.04. (flow_rate alone would give 2.8 and dt alone 2.02.)
      const double r = clothlab::plastic_rest_length(3.0, 2.0, 2.0, {0.25, 2.0, 0.5}, 0.05);
      // What the usual slips give here is worked out in slips.hpp (kFlowFraction).
      INFO(grading::hint(r, grading::slips::kFlowFraction, 1e-9,
                         "the fraction is the product flow_rate dt = 2 * 0.05 = 0.1, so l0' = "
                         "2.04: neither flow_rate nor dt alone"));
      CHECK(r == doctest::Approx(2.04).epsilon(1e-12));
    }
    {
      // Stretched to 3: target 2.4, l0' = 2 + 0.3 (2.4 - 2) = 2.12.
      const double r = clothlab::plastic_rest_length(3.0, 2.0, 2.0, limits, 0.03);
      INFO(
          "flow only part of the way: l0' = l0 + min(1, flow_rate dt) (target - l0) = "
          "2 + 0.3 (2.4 - 2) = 2.12 with flow_rate = 10 1/s and dt = 0.03 s");
      CHECK(r == doctest::Approx(2.12).epsilon(1e-12));
    }
    {
      // Compressed to 1.2: target 1.6, l0' = 2 + 0.3 (1.6 - 2) = 1.88.
      const double r = clothlab::plastic_rest_length(1.2, 2.0, 2.0, limits, 0.03);
      INFO(
          "a compressed spring flows the same fraction toward its own target: "
          "l0' = 2 + 0.3 (1.6 - 2) = 1.88");
      CHECK(r == doctest::Approx(1.88).epsilon(1e-12));
    }
  }

  TEST_CASE("ex06.1 plastic flow never overshoots the current length nor adds energy" * POINTS(1)) {
    // The target l / (1 +- yield_strain) lies between l0 and l whenever |strain| > yield_strain,
    // and l0' moves a fraction in [0, 1] of the way to it, so l0' lies between l0 and l and
    // |l - l0'| <= |l - l0|: the spring's energy ks (l - l0)^2 / 2 can only go down. With
    // l_built chosen so that l0 is within l_built (1 +- max_strain), the clamp keeps this.
    // Every result must also be positive and finite.
    // One of them by hand: l0 = l_built = 2, l = 1.7 * 2 = 3.4, yield_strain = 0.2, flow_rate
    // = 30 1/s, dt = 0.02 s: target 3.4 / 1.2 = 17/6, fraction 0.6, l0' = 2 + 0.6 (17/6 - 2) =
    // 2.5, within the clamp [0.2, 3.8].
    {
      const double r = clothlab::plastic_rest_length(3.4, 2.0, 2.0, {0.2, 30.0, 0.9}, 0.02);
      INFO("l = 3.4, l0 = l_built = 2, yield_strain = 0.2, flow_rate dt = 0.6: l0' = 2.5; got "
           << r);
      CHECK(r == doctest::Approx(2.5).epsilon(1e-12));
    }
    const std::array<double, 3> rest = {0.5, 1.0, 2.0};
    const std::array<double, 10> ratios = {0.3, 0.6, 0.85, 0.95, 1.0, 1.04, 1.2, 1.7, 3.0, 5.0};
    const std::array<double, 3> builts = {1.0, 0.8, 1.25};  // l0 / l_built
    const std::array<double, 3> steps = {0.001, 0.02, 0.5};
    const std::array<PlasticLimits, 2> limits = {{{0.05, 10.0, 0.5}, {0.2, 30.0, 0.9}}};
    for (const PlasticLimits& lim : limits) {
      for (double l0 : rest) {
        for (double ratio : ratios) {
          for (double b : builts) {
            for (double dt : steps) {
              const double l = ratio * l0, l_built = l0 / b;
              const double r = clothlab::plastic_rest_length(l, l0, l_built, lim, dt);
              INFO("l = " << l << ", l0 = " << l0 << ", l_built = " << l_built
                          << ", yield_strain = " << lim.yield_strain
                          << ", flow_rate = " << lim.flow_rate << " 1/s, dt = " << dt
                          << " s, max_strain = " << lim.max_strain << ": got l0' = " << r);
              {
                INFO("the rest length must stay positive and finite");
                CHECK(std::isfinite(r));
                CHECK(r > 0.0);
              }
              {
                INFO(
                    "l0' must lie between l0 and l: the target l / (1 + yield_strain) "
                    "(stretched) or l / (1 - yield_strain) (compressed) is between them, and "
                    "l0 moves at most the whole way, min(1, flow_rate dt)");
                CHECK(r >= std::min(l, l0) * (1.0 - 1e-12));
                CHECK(r <= std::max(l, l0) * (1.0 + 1e-12));
              }
              {
                INFO(
                    "plastic flow must never add energy: |l - l0'| <= |l - l0|, the spring "
                    "relaxes toward its current length and never past it");
                CHECK(std::abs(l - r) <= std::abs(l - l0) + 1e-12 * l0);
              }
            }
          }
        }
      }
    }
  }

  TEST_CASE("ex06.1 the permanent change is clamped around the built length" * POINTS(1)) {
    // Built at l_built = 1 with max_strain = 0.2: l0 must stay in [0.8, 1.2] for good.
    // yield_strain = 0.1, flow_rate dt = 10 * 1 = 10 (full flow).
    const PlasticLimits limits{0.1, 10.0, 0.2};
    {
      // Already stretched for good to l0 = 1.1, now pulled to l = 2: strain = 0.9 / 1.1 > 0.1,
      // target = 2 / 1.1 = 1.818..., clamped to l_built (1 + 0.2) = 1.2. (Clamping around l0
      // would give 1.1 * 1.2 = 1.32; no clamp, 1.818.)
      const double r = clothlab::plastic_rest_length(2.0, 1.1, 1.0, limits, 1.0);
      INFO(
          "clamp around l_built, not l0: a spring built at 1 m with max_strain 0.2 never gets a "
          "rest length above 1.2 m, however far it is pulled and whatever its current l0");
      CHECK(r == doctest::Approx(1.2).epsilon(1e-12));
    }
    {
      // Already compressed for good to l0 = 0.9, now squeezed to l = 0.3: strain = -2/3,
      // target = 0.3 / 0.9 = 0.333..., clamped to l_built (1 - 0.2) = 0.8. (Around l0: 0.72.)
      const double r = clothlab::plastic_rest_length(0.3, 0.9, 1.0, limits, 1.0);
      // What the usual slips give here is worked out in slips.hpp (kClampBelow).
      INFO(grading::hint(r, grading::slips::kClampBelow, 1e-9,
                         "clamp around l_built, not l0: a spring built at 1 m with max_strain 0.2 "
                         "never gets a rest length below 0.8 m"));
      CHECK(r == doctest::Approx(0.8).epsilon(1e-12));
    }
    {
      // Crushed to l = 0.001 from l0 = l_built = 1 with max_strain = 0.5: target = 0.001 / 0.9,
      // clamped to 0.5: still a positive, finite rest length.
      const double r = clothlab::plastic_rest_length(0.001, 1.0, 1.0, {0.1, 10.0, 0.5}, 1.0);
      INFO(
          "a crushed spring keeps a positive rest length: the clamp to "
          "[l_built (1 - max_strain), l_built (1 + max_strain)] = [0.5, 1.5] comes last");
      CHECK(std::isfinite(r));
      CHECK(r == doctest::Approx(0.5).epsilon(1e-12));
    }
  }

  // --- Exercise ex06.2: choosing the springs that tear -------------------------------------------

  TEST_CASE("ex06.2 only springs strictly over the limit tear" * POINTS(1)) {
    // tear_strain = 0.5, no limit on the count (max_tears = 0). Strains: 0.1 (no), 0.3 (no),
    // 0.5 (exactly at the limit: no), 0.5000001 (yes), -0.7 (compressed: no), 0.9 (yes).
    const std::vector<double> strain = {0.1, 0.3, 0.5, 0.5000001, -0.7, 0.9};
    const std::vector<Ends> ends = {{0, 1}, {1, 2}, {2, 3}, {3, 4}, {4, 5}, {5, 6}};
    const std::vector<size_t> torn = clothlab::select_tears(strain, ends, 0.5, 0);
    // All below the limit, and no springs at all: nothing tears.
    const std::vector<size_t> none =
        clothlab::select_tears({0.1, 0.5, -2.0}, {{0, 1}, {1, 2}, {2, 3}}, 0.5, 0);
    const std::vector<size_t> empty = clothlab::select_tears({}, {}, 0.5, 3);
    INFO("got " << show(torn));
    {
      INFO(
          "a spring tears only when its strain is strictly larger than tear_strain: 0.5 exactly "
          "holds, 0.5000001 tears, and a compressed spring (strain -0.7) never tears; expected "
          "[3, 5]");
      CHECK(torn == std::vector<size_t>{3, 5});
    }
    {
      INFO("springs at or below the limit must not tear: expected [], got " << show(none));
      CHECK(none.empty());
    }
    {
      INFO("no springs, no tears: an empty input gives an empty output, got " << show(empty));
      CHECK(empty.empty());
    }
  }

  TEST_CASE("ex06.2 without a cap every spring over the limit tears" * POINTS(1)) {
    // tear_strain = 1: over the limit are positions 0 (2.0), 2 (1.5), 3 (3.0) and 5 (1.1).
    const std::vector<double> strain = {2.0, 0.1, 1.5, 3.0, 0.2, 1.1};
    const std::vector<Ends> ends = {{0, 1}, {1, 2}, {2, 3}, {3, 4}, {4, 5}, {5, 6}};
    const std::vector<size_t> expected = {0, 2, 3, 5};
    // max_tears = 0 means no limit; max_tears = 4 (exactly as many) and 10 (more) keep all.
    const std::vector<size_t> uncapped = clothlab::select_tears(strain, ends, 1.0, 0);
    const std::vector<size_t> exact = clothlab::select_tears(strain, ends, 1.0, 4);
    const std::vector<size_t> loose = clothlab::select_tears(strain, ends, 1.0, 10);
    {
      INFO(
          "max_tears = 0 means no limit: every spring over the limit tears, returned as "
          "positions in ascending order; expected [0, 2, 3, 5], got "
          << show(uncapped));
      CHECK(uncapped == expected);
    }
    {
      INFO(
          "a cap of max_tears = 4 or 10 with only 4 springs over the limit keeps them all, "
          "still in ascending order; expected [0, 2, 3, 5], got "
          << show(exact) << " and " << show(loose));
      CHECK(exact == expected);
      CHECK(loose == expected);
    }
  }

  TEST_CASE("ex06.2 a cap on the count keeps the most strained springs" * POINTS(1)) {
    // tear_strain = 1: all but position 2 are over. Ranked by strain: 3.0 (position 1),
    // 2.9 (5), 2.5 (3), 1.8 (4), 1.3 (6), 1.2 (0).
    const std::vector<double> strain = {1.2, 3.0, 0.1, 2.5, 1.8, 2.9, 1.3};
    const std::vector<Ends> ends = {{0, 1}, {1, 2}, {2, 3}, {3, 4}, {4, 5}, {5, 6}, {6, 7}};
    const std::vector<size_t> three = clothlab::select_tears(strain, ends, 1.0, 3);
    const std::vector<size_t> one = clothlab::select_tears(strain, ends, 1.0, 1);
    {
      // The three most strained: positions 1, 5 and 3, returned ascending: [1, 3, 5].
      // What the usual slips give here is worked out in slips.hpp (kTearCap).
      INFO(grading::hint(three, grading::slips::kTearCap, 0.0,
                         "with max_tears = 3 only the 3 most strained springs tear (strains 3.0, "
                         "2.9, 2.5), not the first 3 over the limit; return positions in ascending "
                         "order; expected [1, 3, 5], got " +
                             show(three)));
      CHECK(strictly_ascending(three));
      CHECK(three == std::vector<size_t>{1, 3, 5});
    }
    {
      INFO("with max_tears = 1 only the most strained spring (position 1) tears; got "
           << show(one));
      CHECK(one == std::vector<size_t>{1});
    }
  }

  TEST_CASE("ex06.2 equal strains are broken by the ends not by the position" * POINTS(1)) {
    // Four springs at the same strain 2.0 (tear_strain = 1) plus one at 2.5. Their ends in
    // lexicographic order: (2, 7) at position 3, (2, 9) at 1, (3, 8) at 0, (4, 6) at 2.
    // Breaking ties by position would pick 0 first; by the first index only, (2, 9) at 1; by
    // the second only, (4, 6) at 2.
    const std::vector<double> strain = {2.0, 2.0, 2.0, 2.0, 2.5};
    const std::vector<Ends> ends = {{3, 8}, {2, 9}, {4, 6}, {2, 7}, {7, 8}};
    // max_tears = 2: the 2.5 at position 4, then the first tie, (2, 7) at 3: [3, 4].
    const std::vector<size_t> two = clothlab::select_tears(strain, ends, 1.0, 2);
    // max_tears = 3: the 2.5, then (2, 7) at 3 and (2, 9) at 1: [1, 3, 4].
    const std::vector<size_t> three = clothlab::select_tears(strain, ends, 1.0, 3);
    {
      INFO(
          "ties must be broken by the ends, not by list position, or the tear depends on how "
          "the cloth was built: among equal strains the spring with the smaller ends pair "
          "(compared lexicographically, first index then second) goes first; expected [3, 4], "
          "got "
          << show(two));
      CHECK(two == std::vector<size_t>{3, 4});
    }
    {
      INFO(
          "the next tie in lexicographic order is (2, 9) at position 1: (2, 7) < (2, 9) < "
          "(3, 8) < (4, 6); expected [1, 3, 4], got "
          << show(three));
      CHECK(three == std::vector<size_t>{1, 3, 4});
    }
  }

  TEST_CASE("ex06.2 the choice does not depend on the order the springs are stored in" *
            POINTS(1)) {
    // The same eight springs, stored in four different orders. tear_strain = 1, max_tears = 3.
    // Over the limit: (0, 1) at 1.4, (1, 2), (0, 4), (1, 5) and (2, 6) at 2.0, (3, 4) at 3.5;
    // (2, 3) at 0.9 is below and (4, 5) at exactly 1.0 holds. The most strained is (3, 4); the
    // four-way tie at 2.0 goes by ends: (0, 4) < (1, 2) < (1, 5) < (2, 6), so (0, 4) and (1, 2).
    // Whatever the order, the torn springs are (0, 4), (1, 2) and (3, 4).
    const std::array<TearSpring, 8> springs = {{{1.4, {0, 1}},
                                                {2.0, {1, 2}},
                                                {0.9, {2, 3}},
                                                {2.0, {0, 4}},
                                                {2.0, {1, 5}},
                                                {3.5, {3, 4}},
                                                {1.0, {4, 5}},
                                                {2.0, {2, 6}}}};
    const std::vector<Ends> expected = {{0, 4}, {1, 2}, {3, 4}};
    const std::array<std::array<size_t, 8>, 4> orders = {{{0, 1, 2, 3, 4, 5, 6, 7},
                                                          {7, 6, 5, 4, 3, 2, 1, 0},
                                                          {7, 4, 2, 1, 6, 3, 0, 5},
                                                          {4, 7, 5, 3, 0, 6, 1, 2}}};
    for (const auto& order : orders) {
      std::vector<double> strain;
      std::vector<Ends> ends;
      for (size_t k : order) {
        strain.push_back(springs[k].strain);
        ends.push_back(springs[k].ends);
      }
      const std::vector<size_t> torn = clothlab::select_tears(strain, ends, 1.0, 3);
      std::vector<Ends> chosen;
      for (size_t k : torn) {
        if (k < ends.size()) chosen.push_back(ends[k]);
      }
      std::sort(chosen.begin(), chosen.end());
      INFO("springs stored as " << show(ends) << ": got positions " << show(torn)
                                << ", the springs " << show(chosen));
      {
        INFO("return positions in ascending order, each at most once, all within the list");
        CHECK(strictly_ascending(torn));
        CHECK(std::all_of(torn.begin(), torn.end(), [&](size_t k) { return k < ends.size(); }));
      }
      {
        INFO(
            "the same cloth must tear the same way whatever order its springs are stored in: "
            "rank by strain, break ties by the ends (not by list position); expected the "
            "springs "
            << show(expected));
        CHECK(chosen == expected);
      }
    }
  }

}  // TEST_SUITE("ex06")
