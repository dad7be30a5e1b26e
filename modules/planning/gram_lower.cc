#include "planning/gram_lower.h"

#include <cstring>

namespace selfcal::planning::internal {

namespace {

// One tile of s += sign w w^T: rows r0 .. r0 + kRows - 1 (kRows a multiple of the vector's lanes) by columns
// c0 .. c0 + 3, summed over every column of w in registers; only its entries on or below the diagonal are
// written.
template <typename Vector, int kRows>
__attribute__((always_inline)) inline void Tile(double sign, const double* w, int ld, int rows, int cols, int r0, int c0,
                                                double* s, int lds) {
  constexpr int kLanes = sizeof(Vector) / sizeof(double), kVectors = kRows / kLanes;
  Vector acc[4][kVectors] = {};
  const double* wk = w;
  for (int k = 0; k < cols; ++k, wk += ld) {
    Vector a[kVectors];
    for (int v = 0; v < kVectors; ++v) std::memcpy(&a[v], wk + r0 + v * kLanes, sizeof(Vector));
    for (int j = 0; j < 4; ++j) {
      const double x = wk[c0 + j];
      for (int v = 0; v < kVectors; ++v) acc[j][v] += a[v] * x;
    }
  }
  for (int j = 0; j < 4 && c0 + j < rows; ++j) {
    for (int i = 0; i < kRows && r0 + i < rows; ++i) {
      if (r0 + i >= c0 + j) s[(c0 + j) * lds + r0 + i] += sign * acc[j][i / kLanes][i % kLanes];
    }
  }
}

// One row r of the same, columns c0 .. c0 + 3 as vectors (the rows below the last full tile).
template <typename Vector>
__attribute__((always_inline)) inline void RowTile(double sign, const double* w, int ld, int cols, int r, int c0,
                                                   double* s, int lds) {
  constexpr int kLanes = sizeof(Vector) / sizeof(double), kVectors = 4 / kLanes;
  Vector acc[kVectors] = {};
  const double* wk = w;
  for (int k = 0; k < cols; ++k, wk += ld) {
    const double x = wk[r];
    for (int v = 0; v < kVectors; ++v) {
      Vector b;
      std::memcpy(&b, wk + c0 + v * kLanes, sizeof(Vector));
      acc[v] += b * x;
    }
  }
  for (int j = 0; j < 4 && c0 + j <= r; ++j) s[(c0 + j) * lds + r] += sign * acc[j / kLanes][j % kLanes];
}

// Every product w_r . w_c is summed over k in order with one multiply and one add per term, whatever the tile
// shape: the tiles only decide which sums share registers.
template <typename Vector, int kTallRows>
__attribute__((always_inline)) inline void GramKernel(double sign, const double* w, int ld, int rows, int cols,
                                                      double* s, int lds) {
  for (int c0 = 0; c0 < rows; c0 += 4) {
    int r0 = c0;
    for (; r0 + kTallRows <= rows; r0 += kTallRows) Tile<Vector, kTallRows>(sign, w, ld, rows, cols, r0, c0, s, lds);
    for (; r0 + 4 <= rows; r0 += 4) Tile<Vector, 4>(sign, w, ld, rows, cols, r0, c0, s, lds);
    for (; r0 < rows; ++r0) RowTile<Vector>(sign, w, ld, cols, r0, c0, s, lds);
  }
}

using Lanes2 = double __attribute__((vector_size(16)));
#if defined(__x86_64__) && defined(__GNUC__)
using Lanes4 = double __attribute__((vector_size(32)));
__attribute__((target("avx"))) void GramAvx(double sign, const double* w, int ld, int rows, int cols, double* s,
                                            int lds) {
  GramKernel<Lanes4, 8>(sign, w, ld, rows, cols, s, lds);
}
bool HasAvx() {
  static const bool has = __builtin_cpu_supports("avx");
  return has;
}
#endif

}  // namespace

void AddGramLowerPortable(double sign, const double* w, int ld, int rows, int cols, double* s, int lds) {
  GramKernel<Lanes2, 4>(sign, w, ld, rows, cols, s, lds);
}

bool AddGramLowerAvx(double sign, const double* w, int ld, int rows, int cols, double* s, int lds) {
#if defined(__x86_64__) && defined(__GNUC__)
  if (!HasAvx()) return false;
  GramAvx(sign, w, ld, rows, cols, s, lds);
  return true;
#else
  (void)sign, (void)w, (void)ld, (void)rows, (void)cols, (void)s, (void)lds;
  return false;
#endif
}

void AddGramLower(double sign, const double* w, int ld, int rows, int cols, double* s, int lds) {
  if (!AddGramLowerAvx(sign, w, ld, rows, cols, s, lds)) AddGramLowerPortable(sign, w, ld, rows, cols, s, lds);
}

}  // namespace selfcal::planning::internal
