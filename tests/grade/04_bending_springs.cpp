// Grading tests for lesson 04, bending springs (exercise ex04.1).
//
// Every expected value is worked out in the comment beside it, from the lesson's definition of
// the bending pairs, (r,c)-(r,c+2) and (r,c)-(r+2,c); none comes from the reference solution.
// A pair may be listed either way round, (a, b) or (b, a), and the list in any order: the tests
// compare sorted lists of (smaller, larger) index pairs.
#include <algorithm>
#include <array>
#include <iterator>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "clothlab/bodies/cloth.hpp"
#include "grading.hpp"

using clothlab::Index;
using clothlab::IndexPair;

namespace {

struct GridSize {
  Index rows, cols;
};

// Each pair as (smaller, larger), the list sorted: two lists hold the same springs exactly when
// their canonical forms are equal.
std::vector<IndexPair> canonical(std::vector<IndexPair> pairs) {
  for (IndexPair& p : pairs) {
    if (p.first > p.second) std::swap(p.first, p.second);
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

// "(0, 2) (0, 6) ...", cut after 40 pairs so a failure message stays readable.
std::string show(const std::vector<IndexPair>& pairs) {
  if (pairs.empty()) return "no pairs";
  std::ostringstream out;
  for (size_t k = 0; k < pairs.size(); ++k) {
    if (k == 40) {
      out << " ... (" << pairs.size() << " pairs in all)";
      break;
    }
    out << (k == 0 ? "" : " ") << "(" << pairs[k].first << ", " << pairs[k].second << ")";
  }
  return out.str();
}

// True when the two lists hold the same pairs (both given in canonical form).
bool same_pairs(const std::vector<IndexPair>& a, const std::vector<IndexPair>& b) {
  return a == b;
}

// The bending pairs found by brute force, from what they mean rather than how a loop builds
// them: every two particles a < b of the grid that lie on one row two columns apart, or on one
// column two rows apart. Particle a sits at row a / cols, column a % cols.
std::vector<IndexPair> bending_pairs_by_definition(Index rows, Index cols) {
  std::vector<IndexPair> pairs;
  const Index n = rows * cols;
  for (Index a = 0; a < n; ++a) {
    for (Index b = a + 1; b < n; ++b) {
      const Index ra = a / cols, ca = a % cols, rb = b / cols, cb = b % cols;
      const bool along_row = ra == rb && cb - ca == 2;
      const bool down_column = ca == cb && rb - ra == 2;
      if (along_row || down_column) pairs.emplace_back(a, b);
    }
  }
  return pairs;  // already sorted: a, then b, increase
}

}  // namespace

TEST_SUITE("ex04") {
  TEST_CASE("ex04.1 a 3x3 grid has six bending pairs worked by hand" * POINTS(2)) {
    // Particles numbered r * 3 + c:    0 1 2
    //                                  3 4 5
    //                                  6 7 8
    // Along the rows, two apart: 0-2, 3-5, 6-8. Down the columns: 0-6, 1-7, 2-8. The centre
    // particle 4 has no bending spring: nothing lies two away from it inside the grid.
    // Sorted as (smaller, larger): (0,2) (0,6) (1,7) (2,8) (3,5) (6,8).
    const std::vector<IndexPair> got = canonical(clothlab::bending_pairs(3, 3));
    const std::vector<IndexPair> expected = {{0, 2}, {0, 6}, {1, 7}, {2, 8}, {3, 5}, {6, 8}};
    INFO(
        "a 3x3 grid has the bending pairs 0-2 3-5 6-8 along the rows and 0-6 1-7 2-8 down the "
        "columns, six in all (either way round, in any order). Particles one apart belong to "
        "the structural springs; pairs crossing from the end of a row to the next row are not "
        "two apart");
    CHECK_MESSAGE(same_pairs(got, expected),
                  "got " << show(got) << ", expected " << show(expected));
  }

  TEST_CASE("ex04.1 the number of pairs is rows (cols - 2) plus cols (rows - 2)" * POINTS(1)) {
    // Each row of cols particles has cols - 2 pairs two apart, each column of rows particles
    // has rows - 2, and a side with only 2 particles has none:
    //   3 x 3:  3 * 1 + 3 * 1 = 6       4 x 5:  4 * 3 + 5 * 2 = 22     5 x 4: 5 * 2 + 4 * 3 = 22
    //   2 x 2:  0 + 0 = 0               2 x 5:  2 * 3 + 0 = 6          5 x 2: 0 + 2 * 3 = 6
    //   10 x 7: 10 * 5 + 7 * 8 = 106
    struct Expected {
      GridSize size;
      size_t count;
    };
    // The 4 x 5 grid comes first: its count tells the usual slips apart (slips.hpp).
    const std::array<Expected, 7> table = {{{{4, 5}, 22},
                                            {{3, 3}, 6},
                                            {{5, 4}, 22},
                                            {{2, 2}, 0},
                                            {{2, 5}, 6},
                                            {{5, 2}, 6},
                                            {{10, 7}, 106}}};
    for (const Expected& e : table) {
      const std::vector<IndexPair> got = clothlab::bending_pairs(e.size.rows, e.size.cols);
      INFO("a " << e.size.rows << " x " << e.size.cols << " grid");
      const std::string general =
          "a rows x cols grid has rows (cols - 2) + cols (rows - 2) bending pairs. Too many "
          "usually means each pair was added twice (once from each end) or rows wrap into the "
          "next row; too few means a loop stops one short (c + 2 < cols is the last pair)";
      // The 4 x 5 grid names the slip its count is (slips.hpp, kBendingCount4x5).
      const bool four_by_five = e.size.rows == 4 && e.size.cols == 5;
      const std::string named = four_by_five
                                    ? grading::hint(static_cast<int>(got.size()),
                                                    grading::slips::kBendingCount4x5, 0.0, general)
                                    : general;
      INFO(named);
      CHECK(got.size() == e.count);
    }
  }

  TEST_CASE("ex04.1 every pair joins two particles two apart on one row or one column" *
            POINTS(1)) {
    // Particle i sits at row i / cols, column i % cols, and must be in the grid: 0 <= i < n.
    // A bending pair lies on one row with columns 2 apart, or on one column with rows 2 apart.
    // Non-square grids catch a column step of 2 * rows instead of 2 * cols. The 3 x 4 grid comes
    // first: its list tells apart the slips that mix rows and columns up (slips.hpp,
    // kBendingPairs3x4), and a report names the one an answer is.
    const std::array<GridSize, 5> sizes = {{{3, 4}, {4, 5}, {6, 3}, {3, 7}, {5, 2}}};
    for (const GridSize& g : sizes) {
      const std::vector<IndexPair> got = clothlab::bending_pairs(g.rows, g.cols);
      INFO("a " << g.rows << " x " << g.cols << " grid");
      // What a check below says when it fails: on the 3 x 4 grid, the slip the answer is named
      // first (the grader's one-line hint of a case is its first failure's message).
      const bool three_by_four = g.rows == 3 && g.cols == 4;
      auto named = [&](const std::string& general) {
        return three_by_four
                   ? grading::hint(canonical(got), grading::slips::kBendingPairs3x4, 0.0, general)
                   : general;
      };
      const Index n = g.rows * g.cols;
      std::vector<IndexPair> outside, not_two_apart;  // the offending pairs, as given
      for (const IndexPair& p : got) {
        const Index a = std::min(p.first, p.second), b = std::max(p.first, p.second);
        const bool along_row = a / g.cols == b / g.cols && b - a == 2;
        const bool down_column = a % g.cols == b % g.cols && b - a == 2 * g.cols;
        if (a < 0 || b >= n) {
          outside.push_back(p);
        } else if (!along_row && !down_column) {
          not_two_apart.push_back(p);
        }
      }
      {
        INFO(
            "indices must be grid-local, r * cols + c, between 0 and rows * cols - 1 (do not "
            "add the cloth's first particle: the engine does that)");
        CHECK_MESSAGE(outside.empty(), named("outside the grid: " + show(outside)));
      }
      {
        INFO(
            "a bending pair joins particles two apart: same row and columns c and c + 2 "
            "(index + 2, never wrapping into the next row), or same column and rows r and "
            "r + 2 (index + 2 * cols)");
        CHECK_MESSAGE(not_two_apart.empty(),
                      named("not two apart on a row or a column: " + show(not_two_apart)));
      }
      {
        // And there are rows (cols - 2) + cols (rows - 2) of them: 10, 22, 18, 22 and 6 pairs.
        const size_t count = static_cast<size_t>(g.rows * (g.cols - 2) + g.cols * (g.rows - 2));
        INFO("a " << g.rows << " x " << g.cols << " grid has " << count << " bending pairs; got "
                  << got.size());
        CHECK(got.size() == count);
      }
    }
  }

  TEST_CASE("ex04.1 each bending pair appears once and none is missing" * POINTS(1)) {
    // The expected pairs come from the definition, by brute force over every two particles of
    // the grid (see bending_pairs_by_definition). (a, b) and (b, a) are the same spring: listing
    // both would make that spring twice as stiff.
    const std::array<GridSize, 4> sizes = {{{4, 5}, {6, 3}, {2, 5}, {5, 2}}};
    for (const GridSize& g : sizes) {
      const std::vector<IndexPair> got = canonical(clothlab::bending_pairs(g.rows, g.cols));
      INFO("a " << g.rows << " x " << g.cols << " grid");
      {
        const auto twice = std::adjacent_find(got.begin(), got.end());
        INFO(
            "each pair must be listed once: (a, b) and (b, a), or the same pair from both of "
            "its ends, would be two springs on the same two particles");
        const std::string repeated =
            twice == got.end() ? "" : show({*twice}) + " is listed more than once";
        CHECK_MESSAGE(twice == got.end(), repeated);
      }
      {
        const std::vector<IndexPair> expected = bending_pairs_by_definition(g.rows, g.cols);
        std::vector<IndexPair> missing;
        std::set_difference(expected.begin(), expected.end(), got.begin(), got.end(),
                            std::back_inserter(missing));
        INFO(
            "every particle with a neighbour two along its row, or two down its column, must get "
            "a bending spring to it: check the first and last rows and columns of the grid");
        CHECK_MESSAGE(missing.empty(), "missing " << show(missing));
      }
    }
  }

}  // TEST_SUITE("ex04")
