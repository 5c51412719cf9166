// The matrix-free solve (see matrix_free.h): PGS, coloured PGS and Jacobi over rows, with
// w = M^-1 J^T lambda per body in place of A = J M^-1 J^T.
#include "matrix_free.h"

#include "buffers.h"
#include "lcp.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>

// The 32-byte vectors of the coloured sweeps (Wide) pass by value only between always-inlined
// functions, so no call uses the ABI that -Wpsabi warns of (it warns at the end of the file, where
// the templates are instantiated, so for the whole file).
#pragma GCC diagnostic ignored "-Wpsabi"

namespace cps {
namespace {

using ConstMap6 = Eigen::Map<const Vec6, Eigen::Aligned16>;

// The functions below are templates on the packed row type (MatrixFreeSystem::Row, double, or
// ::FloatRow, float): s's rows of that type.
template <class PackedRow>
std::vector<PackedRow>& packed(MatrixFreeSystem& s) {
  if constexpr (std::is_same_v<PackedRow, MatrixFreeSystem::Row>) {
    return s.rows;
  } else {
    return s.float_rows;
  }
}
template <class PackedRow>
const std::vector<PackedRow>& packed(const MatrixFreeSystem& s) {
  return packed<PackedRow>(const_cast<MatrixFreeSystem&>(s));
}

// A float row fills two whole cache lines (matrix_free.h).
static_assert(sizeof(PackedRow<float>) == 128 && alignof(PackedRow<float>) == 64);

// The number type of a packed row's j (double or float), which its run's coupling shares.
template <class PackedRow>
using ScalarOf = typename decltype(PackedRow::j)::value_type;

// The coupling blocks for the rows of PackedRow: s.coupling (double rows) or s.float_coupling.
template <class PackedRow>
std::vector<ScalarOf<PackedRow>>& coupling_of(MatrixFreeSystem& s) {
  if constexpr (std::is_same_v<ScalarOf<PackedRow>, float>) {
    return s.float_coupling;
  } else {
    return s.coupling;
  }
}

// Six numbers of a packed row (half a of j, say) as a double 6-vector: in place for a double
// row, converted for a float row (every product and sum is then in double).
inline ConstMap6 half(const double* p) { return ConstMap6(p); }
inline Vec6 half(const float* p) { return Eigen::Map<const Eigen::Matrix<float, 6, 1>>(p).cast<double>(); }

// The row index packed at position i.
inline std::size_t row_at(const MatrixFreeSystem& s, std::size_t i) {
  return s.perm.empty() ? i : static_cast<std::size_t>(s.perm[i]);
}

// j_j . w over the row's bodies: sum_i A_ji lambda_i. 6-vector dot products (Eigen sums each in
// pairs, so the additions do not form one long chain); a row on one movable body (its other
// half, in slot b, is the fixed slot whose w is 0) takes one.
template <class PackedRow>
inline double row_times_w(const PackedRow& r, const std::vector<Vec6>& w, int fixed_slot) {
  const double d = half(r.j.data()).dot(w[static_cast<std::size_t>(r.a)]);
  if (r.b == fixed_slot) return d;
  return d + half(r.j.data() + 6).dot(w[static_cast<std::size_t>(r.b)]);
}

// w += M^-1 j^T delta for the row's movable bodies. The fixed slot (static bodies and the world)
// is never written: M^-1 is 0 there, and rows that share only a static body then do not wait on
// each other's stores.
template <class PackedRow>
inline void add_to_w(const PackedRow& r, double delta, std::vector<Vec6>& w, int fixed_slot) {
  if (r.a != fixed_slot) w[static_cast<std::size_t>(r.a)] += delta * half(r.minv_jt.data());
  if (r.b != fixed_slot) w[static_cast<std::size_t>(r.b)] += delta * half(r.minv_jt.data() + 6);
}

template <bool kCoupled, class PackedRow>
inline void bounds(const PackedRow& r, const std::vector<double>& lambda, double& lo, double& hi) {
  detail::force_limits<kCoupled>(r.c_min, r.c_max, r.mu, r.normal_row, lambda.data(), lo, hi);
}

// A block run's coupling g (m (m - 1) / 2 entries) from its m packed rows r: column i holds
// A_ki / A_kk = (j_k . M^-1 j_i^T) / A_kk for the rows k after i.
// kStride: the rows at r[kStride i], the entries at g[kStride e] (a lane of a lane group).
template <int kStride = 1, class PackedRow>
[[gnu::always_inline]] inline void couple_run(const PackedRow* r, int m, ScalarOf<PackedRow>* g) {
  for (int i = 0; i < m; g += kStride * (m - 1 - i), ++i) {
    const PackedRow& r_i = r[kStride * i];
    for (int k = i + 1; k < m; ++k) {
      const PackedRow& r_k = r[kStride * k];
      const double a_ki = half(r_k.j.data()).dot(half(r_i.minv_jt.data())) +
                          half(r_k.j.data() + 6).dot(half(r_i.minv_jt.data() + 6));
      g[kStride * (k - i - 1)] = static_cast<ScalarOf<PackedRow>>(a_ki * r_k.inv_diagonal);
    }
  }
}

// A short run row by row through w (Eq. 7.1.1): rows r[0..m) all on w_a and, when kTwoBodies, w_b.
template <bool kCoupled, bool kTwoBodies, class PackedRow>
[[gnu::always_inline]] inline void sweep_short_run(const PackedRow* r, const double* b, double* l, int m,
                            const std::vector<double>& lambda, Vec6& w_a, Vec6& w_b) {
  for (int i = 0; i < m; ++i) {
    const PackedRow& row = r[i];
    if (row.inv_diagonal == 0.0) continue;  // the row touches no movable body: lambda stays 0
    double lo;
    double hi;
    bounds<kCoupled>(row, lambda, lo, hi);
    double jw = half(row.j.data()).dot(w_a);
    if constexpr (kTwoBodies) jw += half(row.j.data() + 6).dot(w_b);
    const double value = std::clamp(l[i] + (b[i] - jw) * row.inv_diagonal, lo, hi);
    const double delta = value - l[i];
    w_a += delta * half(row.minv_jt.data());
    if constexpr (kTwoBodies) w_b += delta * half(row.minv_jt.data() + 6);
    l[i] = value;
  }
}

// Row i of a block run's chain of clamps (sweep_block, sweep_block_wide): t_i, row i's unclamped
// value, clamped into its bounds gives lambda_i (into l_i); t_i then becomes row i + 1's (g:
// column i of the run's coupling). Returns false, changing only t_i, for a row that touches no
// movable body (lambda_i stays 0); else delta, lambda_i's change, which the caller then takes
// from the later t[k]. The next row's t is carried in a register, so the chain waits on one
// product and one difference a row, not on a store and load of t (the same numbers in the same
// order).
template <bool kCoupled, class PackedRow>
[[gnu::always_inline]] inline bool clamp_row(const PackedRow& row, int i, int m, const ScalarOf<PackedRow>* g,
                                             const std::vector<double>& lambda, const double* t, double& t_i,
                                             double& l_i, double& delta) {
  if (row.inv_diagonal == 0.0) {
    if (i + 1 < m) t_i = t[i + 1];
    return false;
  }
  double lo;
  double hi;
  bounds<kCoupled>(row, lambda, lo, hi);
  const double value = std::clamp(t_i, lo, hi);
  delta = value - l_i;
  l_i = value;
  if (i + 1 < m) t_i = t[i + 1] - g[0] * delta;
  return true;
}

// clamp_row, then the later t[k] take the change one by one (sweep_block).
template <bool kCoupled, class PackedRow>
[[gnu::always_inline]] inline bool chain_row(const PackedRow& row, int i, int m, const ScalarOf<PackedRow>* g,
                                             const std::vector<double>& lambda, double* t, double& t_i,
                                             double& l_i, double& delta) {
  if (!clamp_row<kCoupled>(row, i, m, g, lambda, t, t_i, l_i, delta)) return false;
  for (int k = i + 2; k < m; ++k) t[k] -= g[k - i - 1] * delta;
  return true;
}

// A run of m rows on w_a and (kTwoBodies) w_b as a block; kM = m when known at compile time (the
// loops then unroll), 0 otherwise. g: the run's coupling, the strict lower triangle of its m x m
// block column by column (column i: A_ki / A_kk for k = i+1..m-1).
template <bool kCoupled, bool kTwoBodies, int kM, class PackedRow>
[[gnu::always_inline]] inline void sweep_block(const PackedRow* r, const double* b, double* l, int m_runtime,
                        const ScalarOf<PackedRow>* g, const std::vector<double>& lambda, Vec6& w_a, Vec6& w_b) {
  const int m = kM > 0 ? kM : m_runtime;
  // Unclamped new values against w at the start of the run: independent of each other.
  double t[MatrixFreeSystem::kMaxRun];
  for (int i = 0; i < m; ++i) {
    double jw = half(r[i].j.data()).dot(w_a);
    if constexpr (kTwoBodies) jw += half(r[i].j.data() + 6).dot(w_b);
    t[i] = l[i] + (b[i] - jw) * r[i].inv_diagonal;
  }
  Vec6 dw_a = Vec6::Zero();
  Vec6 dw_b = Vec6::Zero();
  double t_i = t[0];
  for (int i = 0; i < m; g += m - 1 - i, ++i) {
    double delta;
    if (!chain_row<kCoupled>(r[i], i, m, g, lambda, t, t_i, l[i], delta)) continue;
    dw_a += delta * half(r[i].minv_jt.data());
    if constexpr (kTwoBodies) dw_b += delta * half(r[i].minv_jt.data() + 6);
  }
  w_a += dw_a;
  if constexpr (kTwoBodies) w_b += dw_b;
}

// Coloured PGS's block sweep on 4-wide vectors (GCC vector extensions): a row's j and M^-1 j^T
// as three vectors of 4 over the 12 numbers [half a, half b], its body pair's w likewise. Built for
// SSE2 each vector is two registers, built with AVX2 (coloured_sweeps_avx2) one; every lane's
// operation is the same IEEE operation either way, and the horizontal sum has a fixed order, so
// both builds give the same numbers (a test). The same equations as sweep_block, with j . w summed
// in another order (so another state than sweep_block's, by round-off).
using Wide = double __attribute__((vector_size(32)));

// Four numbers of a packed row from p as a Wide (converted from float for a float row, number by
// number: a vector conversion here would be split in halves before it is inlined into the AVX2
// build).
struct WideLoad {
  [[gnu::always_inline]] static Wide load(const double* p) {
    Wide v;
    std::memcpy(&v, p, sizeof v);
    return v;
  }
  [[gnu::always_inline]] static Wide load(const float* p) {
    return Wide{static_cast<double>(p[0]), static_cast<double>(p[1]), static_cast<double>(p[2]),
                static_cast<double>(p[3])};
  }
};

// The terms of a . b over 12 numbers held as three Wides, lane by lane: (a0 b0 + a1 b1) + a2 b2.
[[gnu::always_inline]] inline Wide wide_terms(Wide a0, Wide a1, Wide a2, Wide b0, Wide b1, Wide b2) {
  return (a0 * b0 + a1 * b1) + a2 * b2;
}

// a . b over 12 numbers held as three Wides: wide_terms' lanes summed as (x0 + x2) + (x1 + x3).
[[gnu::always_inline]] inline double wide_dot(Wide a0, Wide a1, Wide a2, Wide b0, Wide b1, Wide b2) {
  const Wide x = wide_terms(a0, a1, a2, b0, b1, b2);
  return (x[0] + x[2]) + (x[1] + x[3]);
}

// w of a body pair as 12 numbers [w_a, w_b] in three Wides (a one-body run's w_b is the fixed
// slot's 0).
[[gnu::always_inline]] inline void load_pair(const Vec6& w_a, const Vec6& w_b, Wide (&w)[3]) {
  w[0] = WideLoad::load(w_a.data());
  w[1] = Wide{w_a[4], w_a[5], w_b[0], w_b[1]};
  w[2] = WideLoad::load(w_b.data() + 2);
}

// w_a and (two: a second movable body) w_b set to load_pair's w plus the change dw.
[[gnu::always_inline]] inline void store_pair(const Wide (&w)[3], const Wide (&dw)[3], bool two, Vec6& w_a,
                                              Vec6& w_b) {
  const Wide n0 = w[0] + dw[0];
  const Wide n1 = w[1] + dw[1];
  std::memcpy(w_a.data(), &n0, sizeof n0);
  w_a[4] = n1[0];
  w_a[5] = n1[1];
  if (two) {
    const Wide n2 = w[2] + dw[2];
    w_b[0] = n1[2];
    w_b[1] = n1[3];
    std::memcpy(w_b.data() + 2, &n2, sizeof n2);
  }
}

// clamp_row, then (sweep_block_wide) the later t[k] take the change four lanes at a time, in the
// aligned Wides of t that hold rows i + 2 and later, with g read from column i shifted so that
// lane k meets A_ki / A_kk. The lanes before i + 2 (rows already clamped) and past m take
// numbers of no use (their g is a neighbouring column's or the coupling's padding): nothing
// reads them again. Every later t[k] takes the same t[k] - g delta as in chain_row.
template <bool kCoupled, class PackedRow>
[[gnu::always_inline]] inline bool chain_row_wide(const PackedRow& row, int i, int m, const ScalarOf<PackedRow>* g,
                                                  const std::vector<double>& lambda, double* t, double& t_i,
                                                  double& l_i, double& delta) {
  if (!clamp_row<kCoupled>(row, i, m, g, lambda, t, t_i, l_i, delta)) return false;
  const Wide d = {delta, delta, delta, delta};
  for (int q = (i + 2) / 4; 4 * q < m; ++q) {
    Wide t_q;
    std::memcpy(&t_q, t + 4 * q, sizeof t_q);
    t_q -= WideLoad::load(g + 4 * q - i - 1) * d;
    std::memcpy(t + 4 * q, &t_q, sizeof t_q);
  }
  return true;
}

template <bool kCoupled, bool kTwoBodies, class PackedRow>
[[gnu::always_inline]] inline void sweep_block_wide(const PackedRow* r, const double* b, double* l, int m,
                                                    const ScalarOf<PackedRow>* g, const std::vector<double>& lambda,
                                                    Vec6& w_a, Vec6& w_b) {
  Wide w[3] = {};  // load_pair
  load_pair(w_a, w_b, w);
  alignas(32) double t[MatrixFreeSystem::kMaxRun + 4];
  for (int i = m; i < m + 4; ++i) t[i] = 0.0;  // lanes past m (see chain_row_wide)
  for (int i = 0; i < m; ++i) {
    const auto* j = r[i].j.data();
    const double jw = wide_dot(WideLoad::load(j), WideLoad::load(j + 4), WideLoad::load(j + 8), w[0], w[1], w[2]);
    t[i] = l[i] + (b[i] - jw) * r[i].inv_diagonal;
  }
  Wide dw[3] = {};
  double t_i = t[0];
  for (int i = 0; i < m; g += m - 1 - i, ++i) {
    double delta;
    if (!chain_row_wide<kCoupled>(r[i], i, m, g, lambda, t, t_i, l[i], delta)) continue;
    const auto* minv_jt = r[i].minv_jt.data();
    dw[0] += delta * WideLoad::load(minv_jt);
    dw[1] += delta * WideLoad::load(minv_jt + 4);
    if constexpr (kTwoBodies) dw[2] += delta * WideLoad::load(minv_jt + 8);
  }
  store_pair(w, dw, kTwoBodies, w_a, w_b);
}

// What a sweep reads and writes, taken out of s once per solve.
template <class PackedRow>
struct SweepData {
  const PackedRow* rows;
  const double* b;
  double* l;  // lambda by position
  Vec6* w;
  ScalarOf<PackedRow>* coupling;
  int fixed_slot;
};

template <class PackedRow>
SweepData<PackedRow> sweep_data(MatrixFreeSystem& s, std::vector<double>& lambda) {
  return {packed<PackedRow>(s).data(), s.b.data(), lambda.data(), s.w.data(), coupling_of<PackedRow>(s).data(),
          static_cast<int>(s.w.size()) - 1};
}

// Coloured PGS's lane group (Run::lanes = kLanes): kLanes block runs of m rows, one in each
// lane, their rows and coupling interleaved. Lane L does what sweep_block_wide does for its run,
// operation for operation (so the same numbers): the unclamped t of each row against w at the
// start, then the chain of clamps, where the four runs' chains advance side by side in one
// vector each step, then each run's w update. A group with a row that touches no movable body
// (rare) takes the lanes' scalar path for that row (kSkips); the others test no lane. kM = m when
// known at compile time (the loops then unroll), 0 otherwise.
template <int kM, bool kCoupled, class PackedRow>
[[gnu::always_inline]] inline void sweep_lanes(const SweepData<PackedRow>& d, const MatrixFreeSystem::Run& run,
                                               const std::vector<double>& lambda, bool couple) {
  constexpr int kL = MatrixFreeSystem::kLanes;
  static_assert(kL == 4, "a lane group fills one Wide");
  const int m = kM > 0 ? kM : run.count;
  const PackedRow* r = d.rows + run.begin;
  const double* b = d.b + run.begin;
  double* l = d.l + run.begin;
  if (couple) {
    for (int lane = 0; lane < kL; ++lane) couple_run<kL>(r + lane, m, d.coupling + run.offset + lane);
  }
  constexpr int kMax = MatrixFreeSystem::kMaxRun;
  Wide t[kMax];    // row i's unclamped values, lane by lane
  Wide lo[kMax];   // row i's bounds (fixed friction)
  Wide hi[kMax];
  Wide delta[kMax];
  Wide w[kL][3] = {};  // each lane's w_a and w_b (load_pair)
  for (int lane = 0; lane < kL; ++lane) {
    load_pair(d.w[static_cast<std::size_t>(r[lane].a)], d.w[static_cast<std::size_t>(r[lane].b)], w[lane]);
  }
  using Mask = long long __attribute__((vector_size(32)));
  Mask none = {};  // -1 in the lanes with a row that touches no movable body
  for (int i = 0; i < m; ++i) {  // the rows in memory order
    const PackedRow* r_i = r + kL * i;
    Wide x[kL];  // wide_terms, lane by lane
    for (int lane = 0; lane < kL; ++lane) {
      const auto* j = r_i[lane].j.data();
      x[lane] = wide_terms(WideLoad::load(j), WideLoad::load(j + 4), WideLoad::load(j + 8), w[lane][0], w[lane][1],
                           w[lane][2]);
    }
    // The four j . w, one a lane, each summed as wide_dot sums: (x0 + x2) + (x1 + x3).
    const Wide s01 = __builtin_shufflevector(x[0], x[1], 0, 1, 4, 5) + __builtin_shufflevector(x[0], x[1], 2, 3, 6, 7);
    const Wide s23 = __builtin_shufflevector(x[2], x[3], 0, 1, 4, 5) + __builtin_shufflevector(x[2], x[3], 2, 3, 6, 7);
    const Wide jw = __builtin_shufflevector(s01, s23, 0, 2, 4, 6) + __builtin_shufflevector(s01, s23, 1, 3, 5, 7);
    const Wide inv = {r_i[0].inv_diagonal, r_i[1].inv_diagonal, r_i[2].inv_diagonal, r_i[3].inv_diagonal};
    t[i] = WideLoad::load(l + kL * i) + (WideLoad::load(b + kL * i) - jw) * inv;
    if constexpr (!kCoupled) {  // bounds<false>: c_min and c_max
      lo[i] = Wide{static_cast<double>(r_i[0].c_min), static_cast<double>(r_i[1].c_min),
                   static_cast<double>(r_i[2].c_min), static_cast<double>(r_i[3].c_min)};
      hi[i] = Wide{static_cast<double>(r_i[0].c_max), static_cast<double>(r_i[1].c_max),
                   static_cast<double>(r_i[2].c_max), static_cast<double>(r_i[3].c_max)};
    }
    none |= inv == Wide{0.0, 0.0, 0.0, 0.0};
  }
  // The chain of clamps, then each lane's w update. kSkips: some rows touch no movable body, and
  // skip says which (per row, a bit a lane).
  const auto chain = [&]<bool kSkips>(const unsigned* skip) {
    const auto* g = d.coupling + run.offset;
    Wide t_i = t[0];
    for (int i = 0; i < m; g += kL * (m - 1 - i), ++i) {
      Wide lo_i;
      Wide hi_i;
      if constexpr (kCoupled) {
        for (int lane = 0; lane < kL; ++lane) {
          double lo_p;
          double hi_p;
          bounds<true>(r[kL * i + lane], lambda, lo_p, hi_p);
          lo_i[lane] = lo_p;
          hi_i[lane] = hi_p;
        }
      } else {
        lo_i = lo[i];
        hi_i = hi[i];
      }
      const Wide l_i = WideLoad::load(l + kL * i);
      if (!kSkips || skip[i] == 0) {
        // std::clamp lane by lane: (t < lo) ? lo : t, then (hi < x) ? hi : x.
        const Wide x = t_i < lo_i ? lo_i : t_i;
        const Wide value = hi_i < x ? hi_i : x;
        delta[i] = value - l_i;
        std::memcpy(l + kL * i, &value, sizeof value);
        if (i + 1 < m) t_i = t[i + 1] - WideLoad::load(g) * delta[i];
        for (int k = i + 2; k < m; ++k) t[k] -= WideLoad::load(g + kL * (k - i - 1)) * delta[i];
        continue;
      }
      for (int lane = 0; lane < kL; ++lane) {  // as chain_row_wide, lane by lane
        double& l_p = l[kL * i + lane];
        const double t_next = i + 1 < m ? t[i + 1][lane] : 0.0;
        if ((skip[i] >> lane & 1u) != 0) {
          delta[i][lane] = 0.0;
          t_i[lane] = t_next;
          continue;
        }
        const double value = std::clamp(t_i[lane], lo_i[lane], hi_i[lane]);
        const double change = value - l_p;
        delta[i][lane] = change;
        l_p = value;
        if (i + 1 < m) t_i[lane] = t_next - g[lane] * change;
        for (int k = i + 2; k < m; ++k) t[k][lane] -= g[kL * (k - i - 1) + lane] * change;
      }
    }
    Wide dw[kL][3] = {};
    for (int i = 0; i < m; ++i) {  // the rows in memory order again
      for (int lane = 0; lane < kL; ++lane) {
        if (kSkips && (skip[i] >> lane & 1u) != 0) continue;
        const auto* minv_jt = r[kL * i + lane].minv_jt.data();
        const double change = delta[i][lane];
        dw[lane][0] += change * WideLoad::load(minv_jt);
        dw[lane][1] += change * WideLoad::load(minv_jt + 4);
        dw[lane][2] += change * WideLoad::load(minv_jt + 8);
      }
    }
    for (int lane = 0; lane < kL; ++lane) {
      const PackedRow& first = r[lane];
      store_pair(w[lane], dw[lane], first.b != d.fixed_slot, d.w[static_cast<std::size_t>(first.a)],
                 d.w[static_cast<std::size_t>(first.b)]);
    }
  };
  if ((none[0] | none[1] | none[2] | none[3]) == 0) {
    chain.template operator()<false>(nullptr);
    return;
  }
  unsigned skip[kMax];
  for (int i = 0; i < m; ++i) {
    skip[i] = 0;
    for (int lane = 0; lane < kL; ++lane) skip[i] |= (r[kL * i + lane].inv_diagonal == 0.0 ? 1u : 0u) << lane;
  }
  chain.template operator()<true>(skip);
}

// One run (see MatrixFreeSystem::Run): a short run row by row through w, a longer one as a block.
// Inlined into the sweeps' loops: as a call per run it cost the pendulum wave's single-row runs
// 20 % more instructions.
// kWide: a block by sweep_block_wide (coloured PGS), else by sweep_block (PGS).
template <bool kCoupled, bool kWide, class PackedRow>
[[gnu::always_inline]] inline void sweep_run(const SweepData<PackedRow>& d, const MatrixFreeSystem::Run& run,
                      const std::vector<double>& lambda, bool couple) {
  if constexpr (kWide) {
    if (run.lanes > 1) {
      // The common sizes unrolled (four contact points with a contact row and one or two friction
      // rows each, or four contact rows alone), any other size as it comes.
      switch (run.count) {
        case 4: sweep_lanes<4, kCoupled>(d, run, lambda, couple); return;
        case 8: sweep_lanes<8, kCoupled>(d, run, lambda, couple); return;
        case 12: sweep_lanes<12, kCoupled>(d, run, lambda, couple); return;
        default: sweep_lanes<0, kCoupled>(d, run, lambda, couple); return;
      }
    }
  }
  const auto first = static_cast<std::size_t>(run.begin);
  const PackedRow* r = d.rows + first;
  const double* b = d.b + first;
  double* l = d.l + first;
  if (r->a == d.fixed_slot) return;  // no movable body: every lambda stays 0
  // The first sweep of a solve forms the coupling of each block run as it reaches it (the rows are
  // then in the cache), not in a pass of its own.
  if (couple && run.offset >= 0) couple_run(r, run.count, d.coupling + run.offset);
  Vec6& w_a = d.w[static_cast<std::size_t>(r->a)];
  const bool two = r->b != d.fixed_slot;
  if (run.offset < 0) {  // a short run: row by row, through w
    if (!two) {
      Vec6 unused;
      sweep_short_run<kCoupled, false>(r, b, l, run.count, lambda, w_a, unused);
    } else {
      sweep_short_run<kCoupled, true>(r, b, l, run.count, lambda, w_a, d.w[static_cast<std::size_t>(r->b)]);
    }
    return;
  }
  Vec6& w_b = d.w[static_cast<std::size_t>(r->b)];
  const auto* g = d.coupling + run.offset;
  if constexpr (kWide) {
    two ? sweep_block_wide<kCoupled, true>(r, b, l, run.count, g, lambda, w_a, w_b)
        : sweep_block_wide<kCoupled, false>(r, b, l, run.count, g, lambda, w_a, w_b);
    return;
  }
  // Two contact points (a contact and two friction rows each), or any other size.
  if (run.count == 6) {
    two ? sweep_block<kCoupled, true, 6>(r, b, l, 6, g, lambda, w_a, w_b)
        : sweep_block<kCoupled, false, 6>(r, b, l, 6, g, lambda, w_a, w_b);
  } else {
    two ? sweep_block<kCoupled, true, 0>(r, b, l, run.count, g, lambda, w_a, w_b)
        : sweep_block<kCoupled, false, 0>(r, b, l, run.count, g, lambda, w_a, w_b);
  }
}

// Asks for the cache lines of a run's packed rows and coupling ahead of its sweep. The sweeps
// stream the rows in order, but the hardware's own prefetching fell behind them
// (docs/benchmarks.md).
template <class PackedRow>
inline void prefetch_run(const SweepData<PackedRow>& d, const MatrixFreeSystem::Run& run) {
  detail::prefetch_lines<false>(d.rows + run.begin,
                                static_cast<std::size_t>(run.count * run.lanes) * sizeof(PackedRow));
  if (run.offset >= 0) __builtin_prefetch(d.coupling + run.offset, 0, 3);
}

// Runs ahead of the one being swept whose rows prefetch_run() asks for.
inline constexpr std::size_t kPrefetchRuns = 4;

// Whether the sweeps over s prefetch its rows.
template <class PackedRow>
inline bool prefetching(const MatrixFreeSystem& s) {
  return packed<PackedRow>(s).size() * sizeof(PackedRow) >= detail::kPrefetchFrom;
}

// The runs [first, the result) of [first, last) that ask for the run kPrefetchRuns after them.
// A bound in the one loop, not a second loop: with two copies of the sweep the compiler stopped
// inlining Eigen's operators (docs/benchmarks.md).
inline std::size_t prefetch_end(bool prefetch, std::size_t first, std::size_t last) {
  return prefetch && last > first + kPrefetchRuns ? last - kPrefetchRuns : first;
}

// PGS over the runs (see MatrixFreeSystem::Run), in the order of s.runs. In a run of m rows on
// bodies a and b, row k's value after rows i < k have changed by delta_i is
//   lambda_k + (b_k - j_k . w_start) / A_kk - sum_{i < k} (A_ki / A_kk) delta_i,
// the same number Eq. 7.1.1 gives through w, in the same order; w_a and w_b take the run's
// sum of M^-1 j_i^T delta_i at its end.
// The three sweeps are [[gnu::flatten]]: built for double and for float rows, they outgrew GCC's
// inlining budget, and an out-of-line Eigen 6-vector += took 10 % of the funnel's step
// (docs/benchmarks.md); flatten inlines every call in them.
template <bool kCoupled, class PackedRow>
[[gnu::flatten]] void pgs_sweeps(MatrixFreeSystem& s, int iterations, std::vector<double>& lambda) {
  const SweepData<PackedRow> d = sweep_data<PackedRow>(s, lambda);
  const MatrixFreeSystem::Run* runs = s.runs.data();
  const std::size_t count = s.runs.size();
  const std::size_t prefetched = prefetch_end(prefetching<PackedRow>(s), 0, count);
  bool couple = !s.coupling_ready;
  for (int it = 0; it < iterations; ++it) {
    for (std::size_t i = 0; i < count; ++i) {
      if (i < prefetched) prefetch_run(d, runs[i + kPrefetchRuns]);
      sweep_run<kCoupled, false>(d, runs[i], lambda, couple);
    }
    couple = false;
  }
}

// A stream read in order (a sweep's packed rows, or its coupling) whose lines up to kAhead bytes
// past the read are asked for, each line once, so the asks spread evenly over the sweep
// (docs/benchmarks.md, "Rows on whole cache lines, asked for evenly"). Addresses as integers: the
// lines may start before the stream and end past it.
struct PrefetchStream {
  static constexpr std::uintptr_t kAhead = 8192;  // bytes
  std::uintptr_t next = 0;  // the first line not asked for yet
  std::uintptr_t end;       // the stream's end
  explicit PrefetchStream(const void* stream_end) : end(reinterpret_cast<std::uintptr_t>(stream_end)) {}
  // Asks for the lines from the one holding `from` (the start of what the sweep reads next; the
  // lines before it are not asked for now) to kAhead bytes past `to` (its end).
  [[gnu::always_inline]] void upto(const void* from, const void* to) {
    next = std::max(next, reinterpret_cast<std::uintptr_t>(from) & ~std::uintptr_t{63});
    const std::uintptr_t stop = std::min(reinterpret_cast<std::uintptr_t>(to) + kAhead, end);
    for (; next < stop; next += 64) __builtin_prefetch(reinterpret_cast<const void*>(next), 0, 3);
  }
};

// The fewest runs in a block that the threads claim (BlockClaims; count): claiming (an atomic
// exchange on a shared line) stays a small part of a block.
constexpr std::size_t kMinBlockRuns = 16;

// Coloured PGS, thread t of `workers` (every thread runs this with its own t): per sweep, the
// overflow's runs on thread 0 in order, then each colour's runs in blocks that the threads claim
// as they come (BlockClaims), with a barrier after each colour. The runs of a colour share no
// movable body: each writes only its own lambdas and its bodies' w, and reads a contact row's
// lambda only from its own run (a manifold's rows are one run or runs of different colours).
template <bool kCoupled, class PackedRow>
[[gnu::always_inline]] inline void coloured_sweeps_body(MatrixFreeSystem& s, int iterations, std::vector<double>& lambda,
                     Workers* workers, int t) {
  const SweepData<PackedRow> d = sweep_data<PackedRow>(s, lambda);
  const auto threads = static_cast<std::size_t>(workers != nullptr ? workers->count() : 1);
  const bool prefetch = prefetching<PackedRow>(s);
  const std::size_t row_count = packed<PackedRow>(s).size();
  const std::size_t coupling_size = coupling_of<PackedRow>(s).size();
  std::optional<BlockClaims> claims;
  if (threads > 1) claims.emplace(*workers, t);
  bool couple = !s.coupling_ready;
  for (int it = 0; it < iterations; ++it) {
    for (std::size_t k = 0; k < ConstraintGraph::kColours; ++k) {
      const std::size_t begin = s.sweep_start[k];
      const std::size_t count = s.sweep_start[k + 1] - begin;
      if (count == 0) continue;  // every thread sees the same counts
      const MatrixFreeSystem::Run* runs = s.runs.data() + begin;
      PrefetchStream row_stream(d.rows + row_count);
      PrefetchStream coupling_stream(d.coupling + coupling_size);
      const auto sweep_runs = [&](std::size_t first, std::size_t last) {
        for (std::size_t i = first; i < last; ++i) {
          const MatrixFreeSystem::Run& run = runs[i];
          if (prefetch) {
            const PackedRow* r = d.rows + run.begin;
            row_stream.upto(r, r + run.count * run.lanes);
            if (run.offset >= 0) {
              const auto* g = d.coupling + run.offset;
              coupling_stream.upto(g, g + run.lanes * run.count * (run.count - 1) / 2);
            }
          }
          sweep_run<kCoupled, true>(d, run, lambda, couple);
        }
      };
      if (!claims) {
        sweep_runs(0, count);
        continue;
      }
      if (k == 0) {  // the overflow: in order, on thread 0
        if (t == 0) sweep_runs(0, count);
      } else {
        const std::size_t blocks = std::clamp(count / kMinBlockRuns, std::size_t{1}, workers->max_blocks());
        claims->stage(blocks);
        for (std::size_t block; claims->next(block);) {
          sweep_runs(count * block / blocks, count * (block + 1) / blocks);
        }
      }
      workers->sync();
    }
    couple = false;
  }
}

// coloured_sweeps_body built for the baseline (SSE2 on x86-64) and, on x86-64, with AVX2: the
// same numbers (sweep_block_wide); solve() takes the AVX2 build where the CPU has it.
template <bool kCoupled, class PackedRow>
[[gnu::flatten]] void coloured_sweeps(MatrixFreeSystem& s, int iterations, std::vector<double>& lambda,
                                      Workers* workers, int t) {
  coloured_sweeps_body<kCoupled, PackedRow>(s, iterations, lambda, workers, t);
}
#if defined(__x86_64__)
template <bool kCoupled, class PackedRow>
[[gnu::flatten, gnu::target("avx2")]] void coloured_sweeps_avx2(MatrixFreeSystem& s, int iterations,
                                                               std::vector<double>& lambda, Workers* workers, int t) {
  coloured_sweeps_body<kCoupled, PackedRow>(s, iterations, lambda, workers, t);
}
#endif

// Whether this solve's coloured sweeps take the AVX2 build.
bool wide_avx2() {
#if defined(__x86_64__)
  static const bool has_avx2 = __builtin_cpu_supports("avx2");
  return has_avx2 && detail::coloured_avx2_allowed();
#else
  return false;
#endif
}

// Projected Jacobi: every row against the w of the previous sweep, then all of them applied.
template <bool kCoupled, class PackedRow>
[[gnu::flatten]] void jacobi_sweeps(MatrixFreeSystem& s, int iterations, std::vector<double>& lambda) {
  const std::size_t c = packed<PackedRow>(s).size();
  const PackedRow* rows = packed<PackedRow>(s).data();
  const double* b = s.b.data();
  double* l = lambda.data();
  const int fixed_slot = static_cast<int>(s.w.size()) - 1;
  for (int k = 0; k < iterations; ++k) {
    for (std::size_t j = 0; j < c; ++j) {
      const PackedRow& row = rows[j];
      if (row.inv_diagonal == 0.0) continue;  // the row touches no movable body: lambda_j stays 0
      double lo;
      double hi;
      bounds<kCoupled>(row, lambda, lo, hi);
      s.next[j] = std::clamp(l[j] + (b[j] - row_times_w(row, s.w, fixed_slot)) * row.inv_diagonal, lo, hi);
    }
    for (std::size_t j = 0; j < c; ++j) {
      if (rows[j].inv_diagonal == 0.0) continue;
      add_to_w(rows[j], s.next[j] - l[j], s.w, fixed_slot);
      l[j] = s.next[j];
    }
  }
}

// Calls f(rows) with s's packed rows of prepare()'s precision (s.rows or s.float_rows).
template <class System, class F>
void with_rows(System& s, F&& f) {
  if (s.precision == RowPrecision::single_precision) {
    f(s.float_rows);
  } else {
    f(s.rows);
  }
}

// Fewest items (rows, bodies, runs) a stage shares among threads (count): below it waking them
// (microseconds, tens on a virtual machine) costs about what the work does.
constexpr std::size_t kMinParallel = 256;

// Coloured PGS reads the paper's rows by position and stores the packed rows at positions, both
// scattered over tens of MB in a pile's step: rows ahead whose lines are asked for (count; the
// right-hand side reads one line of each row, the packing writes four; docs/benchmarks.md).
constexpr std::size_t kReadAhead = 32;
constexpr std::size_t kWriteAhead = 16;

// Coupling entries reserved per row: sum over runs of m (m - 1) / 2 <= (kMaxRun - 1) / 2 *
// (sum of m), so this bound holds for any mix of manifolds (8 bytes x 12 = 96 bytes a row).
constexpr std::size_t kCouplingPerRow = MatrixFreeSystem::kMaxRun / 2;
// Entries before the first block and after the last (zeros): chain_row_wide reads up to 3
// entries either side of a column.
constexpr std::size_t kCouplingPad = 4;

// The offsets of the coupling blocks of s.runs (any order), and room for them (PGS and coloured
// PGS). The first sweep of the next solve forms the blocks (couple_run).
template <class PackedRow>
void place_coupling(MatrixFreeSystem& s) {
  std::size_t coupling_size = kCouplingPad;
  for (MatrixFreeSystem::Run& run : s.runs) {
    const int m = run.count;
    const bool block = m >= MatrixFreeSystem::kMinBlock;
    run.offset = block ? static_cast<int>(coupling_size) : -1;
    if (block) coupling_size += static_cast<std::size_t>(run.lanes * m * (m - 1) / 2);
  }
  // Room for the largest coupling these many rows can need (kCouplingPerRow): it then grows only
  // when the row count does, not whenever more rows happen to sit in blocks than in any earlier
  // step (which a long run meets after warm-up).
  coupling_size += kCouplingPad;
  auto& coupling = coupling_of<PackedRow>(s);
  detail::reserve_with_headroom(coupling,
                                std::max(coupling_size, kCouplingPerRow * packed<PackedRow>(s).size() + 2 * kCouplingPad));
  detail::resize_with_headroom(coupling, coupling_size);
  std::fill_n(coupling.begin(), kCouplingPad, 0);
  std::fill_n(coupling.end() - kCouplingPad, kCouplingPad, 0);
  s.coupling_ready = false;
}

// Runs of consecutive rows on the same two slots in row order, and their coupling blocks' places
// (PGS).
template <class PackedRow>
void build_runs(MatrixFreeSystem& s) {
  const std::vector<PackedRow>& rows = packed<PackedRow>(s);
  const std::size_t c = rows.size();
  s.runs.clear();
  detail::reserve_with_headroom(s.runs, c);
  for (std::size_t r = 0; r < c;) {
    std::size_t end = r + 1;
    while (end < c && end - r < static_cast<std::size_t>(MatrixFreeSystem::kMaxRun) &&
           rows[end].a == rows[r].a && rows[end].b == rows[r].b) {
      ++end;
    }
    s.runs.push_back({static_cast<int>(r), static_cast<int>(end - r), -1});
    r = end;
  }
  place_coupling<PackedRow>(s);
  s.runs_ready = true;
}

// Coloured PGS's sweep order: s.perm (position -> row), its inverse s.position, and s.runs with
// s.sweep_start, colour by colour as sweep_order() takes them. In each colour but the overflow,
// block runs with a movable body and the same row count go kLanes at a time into a lane group
// (Run::lanes), as they come in row order; the others, and a count's last runs short of a group,
// run on their own. The runs of a colour share no movable body, so their order within it
// changes no number. Each colour's runs and rows are counted first, so that the colours are
// then laid out on `workers`' threads at once, each into its own ranges: the same order for
// every thread count.
void coloured_order(MatrixFreeSystem& s, bool lanes, Workers* workers) {
  constexpr int kL = MatrixFreeSystem::kLanes;
  constexpr int kMax = MatrixFreeSystem::kMaxRun;
  constexpr auto kColours = static_cast<std::size_t>(ConstraintGraph::kColours);
  const RowColours& colours = s.colours;
  // The runs of the colour swept k-th, in row order.
  const auto runs_of = [&](std::size_t k) {
    const auto c = static_cast<std::size_t>(sweep_colour(static_cast<int>(k)));
    return std::pair{colours.order.data() + colours.start[c], colours.order.data() + colours.start[c + 1]};
  };
  // Whether run x of the colour swept k-th goes into a lane group.
  const auto grouped = [&](std::size_t k, const RowColours::Run& x) {
    return lanes && k != 0 && x.count >= MatrixFreeSystem::kMinBlock && x.a >= 0;
  };
  // Per colour: its runs once grouped (whole groups of each row count, the rest alone) and rows.
  ColourStarts run_start{};
  ColourStarts row_start{};
  parallel_chunks(workers, kColours, [&](std::size_t k) {
    std::array<std::size_t, kMax + 1> of_count{};  // grouped runs per row count
    std::size_t runs = 0;
    std::size_t rows = 0;
    for (auto [i, end] = runs_of(k); i != end; ++i) {
      const RowColours::Run& x = colours.runs[*i];
      rows += static_cast<std::size_t>(x.count);
      if (grouped(k, x)) {
        ++of_count[static_cast<std::size_t>(x.count)];
      } else {
        ++runs;
      }
    }
    for (const std::size_t n : of_count) runs += n / kL + n % kL;
    run_start[k + 1] = runs;
    row_start[k + 1] = rows;
  });
  for (std::size_t k = 0; k < kColours; ++k) {
    run_start[k + 1] += run_start[k];
    row_start[k + 1] += row_start[k];
  }
  s.sweep_start = run_start;
  detail::resize_with_headroom(s.runs, run_start.back());
  detail::resize_with_headroom(s.perm, row_start.back());
  detail::resize_with_headroom(s.position, row_start.back());
  parallel_chunks(workers, kColours, [&](std::size_t k) {
    MatrixFreeSystem::Run* run = s.runs.data() + run_start[k];
    auto position = static_cast<int>(row_start[k]);
    const auto place = [&](int row) {
      s.perm[static_cast<std::size_t>(position)] = row;
      s.position[static_cast<std::size_t>(row)] = position;
      ++position;
    };
    const auto alone = [&](const RowColours::Run& x) {
      *run++ = {position, x.count, -1, 1};
      for (int row = x.begin; row < x.begin + x.count; ++row) place(row);
    };
    std::array<std::array<std::size_t, kL>, kMax + 1> waiting{};  // per row count: runs (indices)
    std::array<int, kMax + 1> waits{};
    for (auto [i, end] = runs_of(k); i != end; ++i) {
      const RowColours::Run& x = colours.runs[*i];
      if (!grouped(k, x)) {
        alone(x);
        continue;
      }
      const auto m = static_cast<std::size_t>(x.count);
      waiting[m][static_cast<std::size_t>(waits[m]++)] = *i;
      if (waits[m] < kL) continue;
      waits[m] = 0;
      *run++ = {position, x.count, -1, kL};
      for (int row = 0; row < x.count; ++row) {
        for (std::size_t lane = 0; lane < kL; ++lane) place(colours.runs[waiting[m][lane]].begin + row);
      }
    }
    for (std::size_t m = 0; m <= kMax; ++m) {
      for (int w = 0; w < waits[m]; ++w) alone(colours.runs[waiting[m][static_cast<std::size_t>(w)]]);
    }
  });
}

// Coloured PGS: the coupling blocks' places of the runs coloured_order() made.
template <class PackedRow>
void build_coloured_runs(MatrixFreeSystem& s) {
  place_coupling<PackedRow>(s);
  s.runs_ready = true;
}

}  // namespace

namespace detail {
namespace {
std::atomic<bool> avx2_allowed{true};
std::atomic<bool> lanes_allowed{true};
}  // namespace
void allow_coloured_avx2(bool allowed) { avx2_allowed.store(allowed); }
bool coloured_avx2_allowed() { return avx2_allowed.load(); }
void allow_coloured_lanes(bool allowed) { lanes_allowed.store(allowed); }
bool coloured_lanes_allowed() { return lanes_allowed.load(); }
}  // namespace detail

void prepare(MatrixFreeSystem& s, const std::vector<ConstraintRow>& rows,
             const std::vector<Body>& bodies, SolverKind kind, Workers* workers,
             RowPrecision precision, const std::vector<RowSpan>* spans) {
  const int n = static_cast<int>(bodies.size());
  s.runs_ready = false;  // built below (coloured PGS) or by the first PGS solve (Jacobi: never)
  if (kind == SolverKind::coloured_pgs) {
    if (spans == nullptr) {
      colour_rows(rows, bodies, MatrixFreeSystem::kMaxRun, s.colours);
    } else {
      colour_spans(*spans, rows.size(), bodies, MatrixFreeSystem::kMaxRun, s.colours);
    }
    coloured_order(s, detail::coloured_lanes_allowed(), workers);
  } else {
    s.perm.clear();
    s.position.clear();
  }
  detail::resize_with_headroom(s.inv_inertia, bodies.size());
  parallel_blocks(workers, bodies.size(), kMinParallel, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) s.inv_inertia[i] = bodies[i].inv_inertia_world();
  });
  detail::resize_with_headroom(s.diagonal, rows.size());
  detail::resize_with_headroom(s.w, bodies.size() + 1);  // slot n: static bodies and the fixed world, always 0
  // Static bodies and the fixed world share slot n, whose w stays 0 (M^-1 = 0 there).
  const auto slot = [&](int body) {
    return body == kWorldBody || bodies[static_cast<std::size_t>(body)].is_static() ? n : body;
  };
  // Packs `row` into p, with A_jj of the numbers stored; normal_row: the contact row's position.
  const auto pack = [&]<class PackedRow>(const ConstraintRow& row, int normal_row, PackedRow& p) {
    using Scalar = typename decltype(p.j)::value_type;
    p.a = slot(row.body_a);
    p.b = slot(row.body_b);
    p.c_min = static_cast<Scalar>(row.c_min);
    p.c_max = static_cast<Scalar>(row.c_max);
    p.mu = static_cast<Scalar>(row.mu);
    p.normal_row = normal_row;
    p.minv_jt.fill(Scalar{0});
    double diagonal = 0.0;
    for (int half = 0; half < 2; ++half) {
      const int body = half == 0 ? row.body_a : row.body_b;
      const int o = 6 * half;
      for (int k = 0; k < 6; ++k) p.j[static_cast<std::size_t>(o + k)] = static_cast<Scalar>(row.j[o + k]);
      if (body == kWorldBody) continue;
      const Body& bd = bodies[static_cast<std::size_t>(body)];
      if (bd.is_static()) continue;  // M^-1 = 0: nothing to add
      const Vec3 lin = bd.inv_mass * row.j.segment<3>(o);
      const Vec3 ang = s.inv_inertia[static_cast<std::size_t>(body)] * row.j.segment<3>(o + 3);
      for (int k = 0; k < 3; ++k) {
        p.minv_jt[static_cast<std::size_t>(o + k)] = static_cast<Scalar>(lin[k]);
        p.minv_jt[static_cast<std::size_t>(o + 3 + k)] = static_cast<Scalar>(ang[k]);
      }
      for (int k = 0; k < 6; ++k) {
        const auto e = static_cast<std::size_t>(o + k);
        diagonal += static_cast<double>(p.j[e]) * static_cast<double>(p.minv_jt[e]);
      }
    }
    if (p.a == n && p.b != n) {
      // One movable body, in half b: move it to half a, so the sweep reads one half only
      // (row_times_w). The dot products lose only exact zero terms, so nothing changes.
      std::swap_ranges(p.j.begin(), p.j.begin() + 6, p.j.begin() + 6);
      std::swap_ranges(p.minv_jt.begin(), p.minv_jt.begin() + 6, p.minv_jt.begin() + 6);
      std::swap(p.a, p.b);
    }
    p.inv_diagonal = diagonal > 0.0 ? 1.0 / diagonal : 0.0;
    return diagonal;
  };
  // Every row packed into out (s.rows or s.float_rows), then the coloured runs' coupling.
  const auto pack_all = [&]<class PackedRow>(std::vector<PackedRow>& out) {
    detail::resize_with_headroom(out, rows.size());
    parallel_blocks(workers, rows.size(), kMinParallel, [&](std::size_t begin, std::size_t end) {
      if (s.perm.empty()) {
        for (std::size_t i = begin; i < end; ++i) s.diagonal[i] = pack(rows[i], rows[i].normal_row, out[i]);
        return;
      }
      // Coloured PGS: read in row order and stored at the row's position (scattered stores cost
      // less than scattered loads, which the next instructions wait on), built in one place first.
      PackedRow p;
      for (std::size_t i = begin; i < end; ++i) {
        if (i + kWriteAhead < end) {
          const auto ahead = static_cast<std::size_t>(s.position[i + kWriteAhead]);
          detail::prefetch_lines<true>(&out[ahead], sizeof(PackedRow));
        }
        const int normal_row = rows[i].normal_row;
        const auto at = static_cast<std::size_t>(s.position[i]);
        s.diagonal[at] = pack(rows[i], normal_row < 0 ? normal_row : s.position[static_cast<std::size_t>(normal_row)], p);
        out[at] = p;
      }
    });
    if (kind == SolverKind::coloured_pgs) build_coloured_runs<PackedRow>(s);
  };
  s.precision = precision;
  if (precision == RowPrecision::single_precision) {
    s.rows.clear();
    s.coupling.clear();
    pack_all(s.float_rows);
  } else {
    s.float_rows.clear();
    s.float_coupling.clear();
    pack_all(s.rows);
  }
}

void rhs(MatrixFreeSystem& s, const std::vector<ConstraintRow>& rows,
         const std::vector<Body>& bodies, const Eigen::VectorXd& f_ext, double dt,
         TargetTerms terms, Workers* workers) {
  detail::resize_with_headroom(s.b, rows.size());
  // a = v1 / dt + M^-1 f_ext per body, in w's storage (solve() overwrites it).
  detail::resize_with_headroom(s.w, bodies.size() + 1);
  parallel_blocks(workers, bodies.size(), kMinParallel, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const Body& body = bodies[i];
      Vec6& a = s.w[i];
      a.head<3>() = body.inv_mass * body.p / dt;
      a.tail<3>() = s.inv_inertia[i] * body.l / dt;
      if (!body.is_static()) {
        const auto k = static_cast<Eigen::Index>(6 * i);
        a.head<3>() += body.inv_mass * f_ext.segment<3>(k);
        a.tail<3>() += s.inv_inertia[i] * f_ext.segment<3>(k + 3);
      }
    }
  });
  s.w.back().setZero();
  const int fixed_slot = static_cast<int>(bodies.size());
  with_rows(s, [&](const auto& packed_rows) {
    parallel_blocks(workers, rows.size(), kMinParallel, [&](std::size_t begin, std::size_t end) {
      if (terms == TargetTerms::push_from_rest) {  // the bodies at rest, no external force: b = v / dt
        for (std::size_t i = begin; i < end; ++i) s.b[i] = target_velocity(rows[row_at(s, i)], terms) / dt;
        return;
      }
      for (std::size_t i = begin; i < end; ++i) {
        if (!s.perm.empty() && i + kReadAhead < end) __builtin_prefetch(&rows[row_at(s, i + kReadAhead)].push, 0, 3);
        s.b[i] = target_velocity(rows[row_at(s, i)], terms) / dt - row_times_w(packed_rows[i], s.w, fixed_slot);
      }
    });
  });
}

void solve(MatrixFreeSystem& s, const std::vector<ConstraintRow>& rows, FrictionModel friction,
           SolverKind kind, int iterations, std::vector<double>& lambda,
           const std::vector<double>* initial, Workers* workers) {
  const bool coloured = kind == SolverKind::coloured_pgs;
  if (coloured != !s.perm.empty() && !rows.empty()) {
    throw std::logic_error(std::string("matrix-free solve: rows packed for ") +
                           (s.perm.empty() ? "row order" : "coloured-pgs") + ", solved by " +
                           std::string(name_of(kind)));
  }
  // The sweeps run on l, by position: lambda itself in row order, else s.swept.
  std::vector<double>& l = coloured ? s.swept : lambda;
  detail::assign_with_headroom(l, rows.size(), 0.0);  // initial guess 0 (Sec. 7.2) ...
  for (Vec6& w : s.w) w.setZero();
  with_rows(s, [&](const auto& packed_rows) {
    using PackedRow = typename std::decay_t<decltype(packed_rows)>::value_type;
    if (initial != nullptr) {  // ... or the one given, with w = M^-1 J^T lambda to match
      const int fixed_slot = static_cast<int>(s.w.size()) - 1;
      // Consecutive rows on the same two slots (a manifold's contact rows, its friction rows) sum
      // their M^-1 j^T lambda in registers and add it to w once, so the rows do not wait on each
      // other's w stores.
      Vec6 sum_a = Vec6::Zero();
      Vec6 sum_b = Vec6::Zero();
      int a = fixed_slot;
      int b = fixed_slot;
      const auto flush = [&] {
        if (a != fixed_slot) s.w[static_cast<std::size_t>(a)] += sum_a;
        if (b != fixed_slot) s.w[static_cast<std::size_t>(b)] += sum_b;
        sum_a.setZero();
        sum_b.setZero();
      };
      const auto add = [&](std::size_t j) {
        const PackedRow& r = packed_rows[j];
        if (r.inv_diagonal == 0.0) return;  // touches no movable body: stays 0
        if (r.a != a || r.b != b) {
          flush();
          a = r.a;
          b = r.b;
        }
        l[j] = (*initial)[row_at(s, j)];
        sum_a += l[j] * half(r.minv_jt.data());
        sum_b += l[j] * half(r.minv_jt.data() + 6);
      };
      if (coloured) {  // run by run, a lane group's runs one after another
        for (const MatrixFreeSystem::Run& run : s.runs) {
          for (int lane = 0; lane < run.lanes; ++lane) {
            for (int i = 0; i < run.count; ++i) add(static_cast<std::size_t>(run.begin + run.lanes * i + lane));
          }
        }
      } else {
        for (std::size_t j = 0; j < rows.size(); ++j) add(j);
      }
      flush();
    }
    const bool coupled = friction == FrictionModel::coupled;
    if (kind == SolverKind::jacobi) {
      detail::assign_with_headroom(s.next, rows.size(), 0.0);
      coupled ? jacobi_sweeps<true, PackedRow>(s, iterations, l)
              : jacobi_sweeps<false, PackedRow>(s, iterations, l);
    } else if (coloured) {
      const bool avx2 = wide_avx2();
      auto sweeps = [&](Workers* on, int t) {
#if defined(__x86_64__)
        if (avx2) {
          coupled ? coloured_sweeps_avx2<true, PackedRow>(s, iterations, l, on, t)
                  : coloured_sweeps_avx2<false, PackedRow>(s, iterations, l, on, t);
          return;
        }
#endif
        coupled ? coloured_sweeps<true, PackedRow>(s, iterations, l, on, t)
                : coloured_sweeps<false, PackedRow>(s, iterations, l, on, t);
      };
      if (workers == nullptr || workers->count() == 1) {
        sweeps(nullptr, 0);
      } else {
        auto task = [&](int t) { sweeps(workers, t); };
        workers->run(task);
      }
      detail::resize_with_headroom(lambda, rows.size());
      parallel_blocks(workers, rows.size(), kMinParallel, [&](std::size_t begin, std::size_t end) {
        for (std::size_t j = begin; j < end; ++j) lambda[static_cast<std::size_t>(s.perm[j])] = l[j];
      });
    } else {
      if (!s.runs_ready) build_runs<PackedRow>(s);
      coupled ? pgs_sweeps<true, PackedRow>(s, iterations, l)
              : pgs_sweeps<false, PackedRow>(s, iterations, l);
    }
    if (kind != SolverKind::jacobi && iterations > 0) s.coupling_ready = true;  // formed by the first sweep
  });
}

void constraint_forces(const MatrixFreeSystem& s, const std::vector<Body>& bodies,
                       const Eigen::VectorXd& f_ext, Eigen::VectorXd& f, Workers* workers) {
  f.resize(f_ext.size());  // same size every step: no allocation
  parallel_blocks(workers, bodies.size(), kMinParallel, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const auto k = static_cast<Eigen::Index>(6 * i);
      f.segment<6>(k) = f_ext.segment<6>(k);
      const Body& body = bodies[i];
      if (body.is_static()) continue;
      const Vec6& w = s.w[i];
      f.segment<3>(k) += body.mass * w.head<3>();
      f.segment<3>(k + 3) += s.inv_inertia[i].inverse() * w.tail<3>();
    }
  });
}

void residual(const MatrixFreeSystem& s, const std::vector<ConstraintRow>& rows,
              FrictionModel friction, const std::vector<double>& lambda, double& max,
              double& sum_squares) {
  max = 0.0;
  sum_squares = 0.0;
  with_rows(s, [&](const auto& packed_rows) {
    for (std::size_t j = 0; j < rows.size(); ++j) {
      const double diagonal = s.diagonal[j];
      if (!(diagonal > 0.0)) continue;
      const auto& p = packed_rows[j];
      // The bounds read lambda by row index: the contact row's index for a friction row.
      const int normal_row = p.normal_row < 0 || s.perm.empty()
                                 ? p.normal_row
                                 : s.perm[static_cast<std::size_t>(p.normal_row)];
      double lo;
      double hi;
      detail::force_limits(friction == FrictionModel::coupled, p.c_min, p.c_max, p.mu, normal_row,
                           lambda.data(), lo, hi);
      const double Ax = row_times_w(p, s.w, static_cast<int>(s.w.size()) - 1);
      const double r =
          detail::natural_map_residual(lambda[row_at(s, j)], Ax - s.b[j], diagonal, lo, hi);
      max = std::max(max, r);
      sum_squares += r * r;
    }
  });
}

void explicit_system(const MatrixFreeSystem& s, SparseRowMatrix& A, Eigen::VectorXd& b,
                     RowLimits& limits) {
  with_rows(s, [&](const auto& packed_rows) {
    const auto c = static_cast<Eigen::Index>(packed_rows.size());
    const auto slots = 6 * static_cast<Eigen::Index>(s.w.size());  // n bodies and the fixed slot
    // J and (M^-1 J^T)^T over the slots, 12 entries a row; the fixed slot's M^-1 j^T is 0.
    std::vector<Eigen::Triplet<double>> j_entries;
    std::vector<Eigen::Triplet<double>> m_entries;
    j_entries.reserve(static_cast<std::size_t>(12 * c));
    m_entries.reserve(static_cast<std::size_t>(12 * c));
    limits.c_min.resize(c);
    limits.c_max.resize(c);
    limits.mu.resize(c);
    limits.normal_row.resize(static_cast<std::size_t>(c));
    for (Eigen::Index i = 0; i < c; ++i) {
      // Written at its row index: A, b and the limits in row order, as the explicit path's.
      const auto& p = packed_rows[static_cast<std::size_t>(i)];
      const auto r = static_cast<Eigen::Index>(row_at(s, static_cast<std::size_t>(i)));
      for (int half = 0; half < 2; ++half) {
        const Eigen::Index column = 6 * static_cast<Eigen::Index>(half == 0 ? p.a : p.b);
        for (int k = 0; k < 6; ++k) {
          const auto e = static_cast<std::size_t>(6 * half + k);
          j_entries.emplace_back(r, column + k, p.j[e]);
          m_entries.emplace_back(r, column + k, p.minv_jt[e]);
        }
      }
      limits.c_min[r] = p.c_min;
      limits.c_max[r] = p.c_max;
      limits.mu[r] = p.mu;
      limits.normal_row[static_cast<std::size_t>(r)] =
          p.normal_row < 0 || s.perm.empty() ? p.normal_row : s.perm[static_cast<std::size_t>(p.normal_row)];
    }
    SparseRowMatrix J(c, slots);
    SparseRowMatrix MJt(c, slots);
    J.setFromTriplets(j_entries.begin(), j_entries.end());
    MJt.setFromTriplets(m_entries.begin(), m_entries.end());
    A = J * SparseRowMatrix(MJt.transpose());
    b.resize(c);
    for (Eigen::Index i = 0; i < c; ++i) b[static_cast<Eigen::Index>(row_at(s, static_cast<std::size_t>(i)))] = s.b[static_cast<std::size_t>(i)];
  });
}

}  // namespace cps
