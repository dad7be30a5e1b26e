#include "planning/exchange_kernels.h"

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

// A vector of lanes read from (or written to) unaligned memory (through pointers: AVX vectors are not passed
// by value across functions compiled without AVX).
template <typename Vector>
__attribute__((always_inline)) inline void Load(const double* from, Vector* v) {
  std::memcpy(v, from, sizeof(Vector));
}
template <typename Vector>
__attribute__((always_inline)) inline void Store(const Vector* v, double* to) {
  std::memcpy(to, v, sizeof(Vector));
}

// Rows r .. r + lanes - 1 of one dot's two columns: a = f z, then L^-1 (a - b p). T: a vector of lanes, or
// double for the rows left over; every lane does the same operations in the same order.
template <typename T>
__attribute__((always_inline)) inline void MarginalRows(const MarginalDot& d, double i00, double i11, const double* zt,
                                                        int n, int r) {
  T z0, z1, z2, z3, z4, z5, z6, p0, p1, p2;
  Load(zt + r, &z0);
  Load(zt + n + r, &z1);
  Load(zt + 2 * n + r, &z2);
  Load(zt + 3 * n + r, &z3);
  Load(zt + 4 * n + r, &z4);
  Load(zt + 5 * n + r, &z5);
  Load(zt + 6 * n + r, &z6);
  Load(d.p + r, &p0);
  Load(d.p + n + r, &p1);
  Load(d.p + 2 * n + r, &p2);
  const T a0 = d.f[0][0] * z0 + d.f[0][1] * z1 + d.f[0][2] * z2 + d.f[0][3] * z3 + d.f[0][4] * z4 + d.f[0][5] * z5 +
               d.f[0][6] * z6;
  const T a1 = d.f[1][0] * z0 + d.f[1][1] * z1 + d.f[1][2] * z2 + d.f[1][3] * z3 + d.f[1][4] * z4 + d.f[1][5] * z5 +
               d.f[1][6] * z6;
  const T w0 = (a0 - (d.b[0][0] * p0 + d.b[0][1] * p1 + d.b[0][2] * p2)) * i00;
  const T w1 = ((a1 - (d.b[1][0] * p0 + d.b[1][1] * p1 + d.b[1][2] * p2)) - d.l10 * w0) * i11;
  Store(&w0, d.w0 + r);
  Store(&w1, d.w1 + r);
}

template <typename Vector>
__attribute__((always_inline)) inline void MarginalKernel(const MarginalDot* dots, int count, const double* zt, int n) {
  constexpr int kLanes = sizeof(Vector) / sizeof(double);
  for (int i = 0; i < count; ++i) {
    const MarginalDot d = dots[i];
    const double i00 = 1.0 / d.l00, i11 = 1.0 / d.l11;
    int r = 0;
    for (; r + kLanes <= n; r += kLanes) MarginalRows<Vector>(d, i00, i11, zt, n, r);
    for (; r < n; ++r) MarginalRows<double>(d, i00, i11, zt, n, r);
  }
}

using Lanes2 = double __attribute__((vector_size(16)));
#if defined(__x86_64__) && defined(__GNUC__)
using Lanes4 = double __attribute__((vector_size(32)));
__attribute__((target("avx"))) void GramAvx(double sign, const double* w, int ld, int rows, int cols, double* s,
                                            int lds) {
  GramKernel<Lanes4, 8>(sign, w, ld, rows, cols, s, lds);
}
__attribute__((target("avx"))) void MarginalAvx(const MarginalDot* dots, int count, const double* zt, int n) {
  MarginalKernel<Lanes4>(dots, count, zt, n);
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

void MarginalColumnsPortable(const MarginalDot* dots, int count, const double* zt, int n) {
  MarginalKernel<Lanes2>(dots, count, zt, n);
}

bool MarginalColumnsAvx(const MarginalDot* dots, int count, const double* zt, int n) {
#if defined(__x86_64__) && defined(__GNUC__)
  if (!HasAvx()) return false;
  MarginalAvx(dots, count, zt, n);
  return true;
#else
  (void)dots, (void)count, (void)zt, (void)n;
  return false;
#endif
}

void MarginalColumns(const MarginalDot* dots, int count, const double* zt, int n) {
  if (!MarginalColumnsAvx(dots, count, zt, n)) MarginalColumnsPortable(dots, count, zt, n);
}

}  // namespace selfcal::planning::internal
