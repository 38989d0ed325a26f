// bending.hpp: resistance to folding, from springs that skip a particle.
//
// Structural and shear springs keep each cell of the cloth from stretching and skewing, but a
// row of particles can still fold at every particle for free: nothing connects particles that
// are not neighbours. Flexion (bending) springs join particles two apart, (i, j)-(i+2, j) and
// (i, j)-(i, j+2); folding the row shortens them, so they push back. They get their own ks and
// kd, usually much softer than the structural springs: cloth resists bending far less than
// stretching. The pairs are built by bending_pairs() (exercise ex04.1, declared in cloth.hpp);
// the force is the same spring-damper as lesson 02, in an effect named "bending".
#pragma once

#include "clothlab/bodies/cloth.hpp"
#include "clothlab/forces/spring_damper.hpp"

namespace clothlab {

// The bending springs of a cloth grid, ks [N/m] and kd [N s/m], rest lengths measured in x.
// Throws KernelAnswerError (kernel_answer.hpp) if bending_pairs names a particle outside the
// grid (check_bending_pairs).
SpringSet bending_springs(const ClothGrid& grid, double ks, double kd, const Matrix3X& x);

// Throws KernelAnswerError unless every pair joins two different particles of a rows x cols
// grid, numbered 0 to rows cols - 1: what bending_pairs(rows, cols) must return for the engine
// to read the particles it names.
void check_bending_pairs(const std::vector<IndexPair>& pairs, Index rows, Index cols);

}  // namespace clothlab
