// Eigen-decomposition of a symmetric 3x3 matrix by cyclic Jacobi rotations
// (Golub & Van Loan, Matrix Computations, 8.5): the OBB's principal axes.
#pragma once

#include <glm/glm.hpp>

namespace rtcl {

struct SymmetricEigen {
  glm::dvec3 values;   // in descending order
  glm::dmat3 vectors;  // column k belongs to values[k]; orthonormal
};

// At most 32 sweeps (a 3x3 matrix converges to double precision in < 10).
// A zero matrix gives the identity.
SymmetricEigen symmetric_eigen(const glm::dmat3& a);

}  // namespace rtcl
