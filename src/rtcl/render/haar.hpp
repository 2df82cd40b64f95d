// The orthonormal Haar wavelet transform, in place, of sequences and square
// images whose side is a power of two. One level of the 1D transform maps
// x_0 .. x_{n-1} to the averages a_i = (x_{2i} + x_{2i+1}) / sqrt 2 in the
// first half and the details d_i = (x_{2i} - x_{2i+1}) / sqrt 2 in the second;
// the full transform repeats it on the first half down to one value (the sum
// over sqrt n). The 2D transform is the non-standard decomposition (Stollnitz,
// DeRose & Salesin 1995, "Wavelets for computer graphics: a primer"): one
// level on every row, then on every column, of the top-left s x s, for s = n,
// n / 2, ... 2. For the 2x2 group a = (2i, 2j), b = (2i + 1, 2j),
// c = (2i, 2j + 1), d = (2i + 1, 2j + 1) ((x, y), y down) of level s it leaves
// (a + b + c + d) / 2 at (i, j), the x detail (a - b + c - d) / 2 at
// (i + s/2, j), the y detail (a + b - c - d) / 2 at (i, j + s/2) and the
// diagonal one (a - b - c + d) / 2 at (i + s/2, j + s/2). Both are orthogonal:
// energy is preserved and the inverses reconstruct exactly (up to rounding).
#pragma once

#include <cstdint>
#include <vector>

namespace rtcl {

// Throw Error unless x.size() (or n, with data.size() == n * n, row-major)
// is a power of two.
void haar_1d(std::vector<double>& x);
void inverse_haar_1d(std::vector<double>& x);
void haar_2d(std::vector<double>& data, std::uint32_t n);
void inverse_haar_2d(std::vector<double>& data, std::uint32_t n);

}  // namespace rtcl
