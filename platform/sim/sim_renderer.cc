#include "platform/sim/sim_renderer.h"

#include "platform/camera_geometry.h"
#include "platform/field_geometry.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstring>
#include <limits>

#include <emmintrin.h>

#include <opencv2/imgproc.hpp>

namespace slamo::platform {

using Eigen::Vector3d;
using Eigen::Vector3f;

// The render pass is compiled twice, for AVX and for plain x86-64, and the CPU picks one when
// the program starts (function multi-versioning). AVX only brings the VEX encoding here (three
// operands, fewer register copies): the same operations in the same order and no FMA (AVX has
// none), so both versions compute the same bits. The pass's lambdas are inlined into it to be
// compiled for AVX too.
#define SLAMO_ALWAYS_INLINE __attribute__((always_inline))
#define SLAMO_AVX_CLONES __attribute__((target_clones("avx", "default")))

enum class PrimitiveKind { kSphere, kBox, kCylinder, kRing, kPlate, kPrism };

struct SimRenderer::Primitive {
  PrimitiveKind kind = PrimitiveKind::kSphere;
  Vector3d center =
      Vector3d::Zero();               // sphere centre; box/cylinder/ring/plate: (x, y) and unused z
  double radius = 0.0;                // sphere, cylinder, ring outer, plate disc radius
  double inner_radius = 0.0;          // ring
  double half_x = 0.0, half_y = 0.0;  // box (local axes), plate half width
  double z0 = 0.0, z1 = 0.0;          // vertical extent (box, cylinder, ring, plate)
  double cos_yaw = 1.0, sin_yaw = 0.0;
  Vector3d plate_normal = Vector3d::UnitX();  // plate: horizontal normal facing the viewer
  bool plate_disc = true;
  std::vector<Eigen::Vector2d> polygon;       // prism: outline around (x, y), counter-clockwise
  Vector3d albedo = Vector3d::Constant(0.5);  // RGB in [0, 1]
  double opacity = 1.0;
  bool glossy = false;
  int id = 0;
  Vector3d aabb_min = Vector3d::Zero(), aabb_max = Vector3d::Zero();
};

namespace {

using Primitive = SimRenderer::Primitive;

constexpr float kInf = std::numeric_limits<float>::infinity();
// Buffers hold this many pixels beyond the image, for the passes' four-pixel groups.
constexpr size_t kPad = 4;

Vector3d Albedo(const field::SeasonConfig& season, const std::string& colour) {
  const field::Rgb& c = season.colours.at(colour);
  return Vector3d(c.r, c.g, c.b) / 255.0;
}

// Four floats in SSE2 registers with the operators of float: each lane rounds exactly as the
// scalar code does (SSE2 has no FMA and nothing here reassociates), so four pixels shaded at
// once get the bits one pixel at a time got. Eigen's fixed-size 3-vector reductions add as
// x + (y + z); Dot and Normalized below do the same.
struct F4 {
  __m128 m;
  F4() = default;
  explicit F4(__m128 v) : m(v) {}
  F4(float x) : m(_mm_set1_ps(x)) {}  // NOLINT: constants as in the scalar expressions
};
inline F4 operator+(F4 a, F4 b) { return F4(_mm_add_ps(a.m, b.m)); }
inline F4 operator-(F4 a, F4 b) { return F4(_mm_sub_ps(a.m, b.m)); }
inline F4 operator*(F4 a, F4 b) { return F4(_mm_mul_ps(a.m, b.m)); }
inline F4 operator/(F4 a, F4 b) { return F4(_mm_div_ps(a.m, b.m)); }
inline F4 operator-(F4 a) { return F4(_mm_xor_ps(a.m, _mm_set1_ps(-0.0f))); }
inline F4 Sqrt(F4 a) { return F4(_mm_sqrt_ps(a.m)); }
inline F4 MaxZero(F4 a) { return F4(_mm_max_ps(a.m, _mm_setzero_ps())); }  // std::max(0.0f, a)
inline F4 MinOne(F4 a) { return F4(_mm_min_ps(a.m, _mm_set1_ps(1.0f))); }  // std::min(1.0f, a)
inline F4 Load4(const float* p) { return F4(_mm_loadu_ps(p)); }

struct M4 {  // a lane mask: all ones or all zeros
  __m128 m;
};
inline M4 operator<(F4 a, F4 b) { return {_mm_cmplt_ps(a.m, b.m)}; }
inline M4 operator>(F4 a, F4 b) { return {_mm_cmpgt_ps(a.m, b.m)}; }
inline M4 operator<=(F4 a, F4 b) { return {_mm_cmple_ps(a.m, b.m)}; }
inline M4 operator>=(F4 a, F4 b) { return {_mm_cmpge_ps(a.m, b.m)}; }
inline M4 operator==(F4 a, F4 b) { return {_mm_cmpeq_ps(a.m, b.m)}; }
// The negated comparisons, true for NaN as `if (a < b) continue;` lets NaN through.
inline M4 NotLess(F4 a, F4 b) { return {_mm_cmpnlt_ps(a.m, b.m)}; }
inline M4 NotLessEqual(F4 a, F4 b) { return {_mm_cmpnle_ps(a.m, b.m)}; }
inline M4 NotGreaterEqual(F4 a, F4 b) { return {_mm_cmpnge_ps(a.m, b.m)}; }
inline M4 operator&(M4 a, M4 b) { return {_mm_and_ps(a.m, b.m)}; }
inline M4 operator|(M4 a, M4 b) { return {_mm_or_ps(a.m, b.m)}; }
inline M4 AndNot(M4 a, M4 b) { return {_mm_andnot_ps(b.m, a.m)}; }  // a & ~b
inline int Bits(M4 a) { return _mm_movemask_ps(a.m); }
inline F4 Select(M4 mask, F4 a, F4 b) {
  return F4(_mm_or_ps(_mm_and_ps(mask.m, a.m), _mm_andnot_ps(mask.m, b.m)));
}
inline M4 Select(M4 mask, M4 a, M4 b) { return {Select(mask, F4(a.m), F4(b.m)).m}; }

struct V3 {
  F4 x, y, z;
};
inline F4 Dot(const V3& a, const V3& b) { return a.x * b.x + (a.y * b.y + a.z * b.z); }
// Eigen's normalized(): v / |v|, or v itself when |v|^2 is not positive.
inline V3 Normalized(const V3& v) {
  const F4 n2 = Dot(v, v);
  const F4 n = Sqrt(n2);
  const M4 positive = n2 > F4(0.0f);
  return {Select(positive, v.x / n, v.x), Select(positive, v.y / n, v.y),
          Select(positive, v.z / n, v.z)};
}
// x^n by squaring (n >= 0): the highlight exponents, without std::pow per pixel.
inline F4 PowInt4(F4 x, int n) {
  F4 result(1.0f);
  while (n > 0) {
    if (n & 1) result = result * x;
    x = x * x;
    n >>= 1;
  }
  return result;
}

// Four consecutive RGB pixels (12 floats) to and from one register per channel.
inline void LoadRgb4(const Vector3f* p, F4* r, F4* g, F4* b) {
  const float* f = p->data();
  const __m128 a = _mm_loadu_ps(f), c = _mm_loadu_ps(f + 4), e = _mm_loadu_ps(f + 8);
  // a = r0 g0 b0 r1, c = g1 b1 r2 g2, e = b2 r3 g3 b3
  const __m128 ce_r = _mm_shuffle_ps(c, e, _MM_SHUFFLE(1, 1, 2, 2));  // r2 r2 r3 r3
  const __m128 ac_g = _mm_shuffle_ps(a, c, _MM_SHUFFLE(0, 0, 1, 1));  // g0 g0 g1 g1
  const __m128 ce_g = _mm_shuffle_ps(c, e, _MM_SHUFFLE(2, 2, 3, 3));  // g2 g2 g3 g3
  const __m128 ac_b = _mm_shuffle_ps(a, c, _MM_SHUFFLE(1, 1, 2, 2));  // b0 b0 b1 b1
  const __m128 ee_b = _mm_shuffle_ps(e, e, _MM_SHUFFLE(3, 3, 0, 0));  // b2 b2 b3 b3
  r->m = _mm_shuffle_ps(a, ce_r, _MM_SHUFFLE(2, 0, 3, 0));
  g->m = _mm_shuffle_ps(ac_g, ce_g, _MM_SHUFFLE(2, 0, 2, 0));
  b->m = _mm_shuffle_ps(ac_b, ee_b, _MM_SHUFFLE(2, 0, 2, 0));
}
inline void StoreRgb4(Vector3f* p, F4 r, F4 g, F4 b) {
  float* f = p->data();
  const __m128 rg_lo = _mm_unpacklo_ps(r.m, g.m);  // r0 g0 r1 g1
  const __m128 rg_hi = _mm_unpackhi_ps(r.m, g.m);  // r2 g2 r3 g3
  // r0 g0 b0 r1
  const __m128 b0r1 = _mm_shuffle_ps(b.m, r.m, _MM_SHUFFLE(1, 1, 0, 0));  // b0 b0 r1 r1
  const __m128 a = _mm_shuffle_ps(rg_lo, b0r1, _MM_SHUFFLE(2, 0, 1, 0));
  // g1 b1 r2 g2
  const __m128 g1b1 = _mm_shuffle_ps(g.m, b.m, _MM_SHUFFLE(1, 1, 1, 1));  // g1 g1 b1 b1
  const __m128 c = _mm_shuffle_ps(g1b1, rg_hi, _MM_SHUFFLE(1, 0, 2, 0));
  // b2 r3 g3 b3
  const __m128 b2r3 = _mm_shuffle_ps(b.m, r.m, _MM_SHUFFLE(3, 3, 2, 2));  // b2 b2 r3 r3
  const __m128 g3b3 = _mm_shuffle_ps(g.m, b.m, _MM_SHUFFLE(3, 3, 3, 3));  // g3 g3 b3 b3
  const __m128 e = _mm_shuffle_ps(b2r3, g3b3, _MM_SHUFFLE(2, 0, 2, 0));
  _mm_storeu_ps(f, a), _mm_storeu_ps(f + 4, c), _mm_storeu_ps(f + 8, e);
}

// Two doubles in SSE2, as F4 for floats: the double-precision primitives two rays at a time.
struct D2 {
  __m128d m;
  D2() = default;
  explicit D2(__m128d v) : m(v) {}
  D2(double x) : m(_mm_set1_pd(x)) {}  // NOLINT: constants as in the scalar expressions
};
inline D2 operator+(D2 a, D2 b) { return D2(_mm_add_pd(a.m, b.m)); }
inline D2 operator-(D2 a, D2 b) { return D2(_mm_sub_pd(a.m, b.m)); }
inline D2 operator*(D2 a, D2 b) { return D2(_mm_mul_pd(a.m, b.m)); }
inline D2 operator/(D2 a, D2 b) { return D2(_mm_div_pd(a.m, b.m)); }
inline D2 operator-(D2 a) { return D2(_mm_xor_pd(a.m, _mm_set1_pd(-0.0))); }
inline D2 Sqrt(D2 a) { return D2(_mm_sqrt_pd(a.m)); }

struct M2 {
  __m128d m;
};
inline M2 operator<(D2 a, D2 b) { return {_mm_cmplt_pd(a.m, b.m)}; }
inline M2 operator>(D2 a, D2 b) { return {_mm_cmpgt_pd(a.m, b.m)}; }
inline M2 NotLess(D2 a, D2 b) { return {_mm_cmpnlt_pd(a.m, b.m)}; }
inline M2 NotGreater(D2 a, D2 b) { return {_mm_cmpngt_pd(a.m, b.m)}; }
inline M2 NotLessEqual(D2 a, D2 b) { return {_mm_cmpnle_pd(a.m, b.m)}; }
inline M2 NotGreaterEqual(D2 a, D2 b) { return {_mm_cmpnge_pd(a.m, b.m)}; }
inline M2 operator&(M2 a, M2 b) { return {_mm_and_pd(a.m, b.m)}; }
inline M2 operator|(M2 a, M2 b) { return {_mm_or_pd(a.m, b.m)}; }
inline D2 Select(M2 mask, D2 a, D2 b) {
  return D2(_mm_or_pd(_mm_and_pd(mask.m, a.m), _mm_andnot_pd(mask.m, b.m)));
}
inline M2 IsFinite(D2 a) {
  return {_mm_cmplt_pd(_mm_andnot_pd(_mm_set1_pd(-0.0), a.m),
                       _mm_set1_pd(std::numeric_limits<double>::infinity()))};
}
// Two lanes each from two halves, back to four floats (the doubles rounded as static_cast).
inline F4 ToF4(D2 lo, D2 hi) { return F4(_mm_movelh_ps(_mm_cvtpd_ps(lo.m), _mm_cvtpd_ps(hi.m))); }
inline M4 ToM4(M2 lo, M2 hi) {
  return {_mm_shuffle_ps(_mm_castpd_ps(lo.m), _mm_castpd_ps(hi.m), _MM_SHUFFLE(2, 0, 2, 0))};
}

double Luminance(const Vector3d& rgb) {
  return 0.299 * rgb.x() + 0.587 * rgb.y() + 0.114 * rgb.z();
}

void SetAabb(Primitive* p) {
  switch (p->kind) {
    case PrimitiveKind::kSphere:
      p->aabb_min = p->center - Vector3d::Constant(p->radius);
      p->aabb_max = p->center + Vector3d::Constant(p->radius);
      return;
    case PrimitiveKind::kBox: {
      const double ex = std::abs(p->cos_yaw) * p->half_x + std::abs(p->sin_yaw) * p->half_y;
      const double ey = std::abs(p->sin_yaw) * p->half_x + std::abs(p->cos_yaw) * p->half_y;
      p->aabb_min = Vector3d(p->center.x() - ex, p->center.y() - ey, p->z0);
      p->aabb_max = Vector3d(p->center.x() + ex, p->center.y() + ey, p->z1);
      return;
    }
    case PrimitiveKind::kCylinder:
    case PrimitiveKind::kRing:
    case PrimitiveKind::kPrism:
      p->aabb_min = Vector3d(p->center.x() - p->radius, p->center.y() - p->radius, p->z0);
      p->aabb_max = Vector3d(p->center.x() + p->radius, p->center.y() + p->radius, p->z1);
      return;
    case PrimitiveKind::kPlate: {
      const double e = std::max(p->radius, p->half_x) + 0.01;
      p->aabb_min = Vector3d(p->center.x() - e, p->center.y() - e, p->z0);
      p->aabb_max = Vector3d(p->center.x() + e, p->center.y() + e, p->z1);
      return;
    }
  }
}

// Ray o + t d against a vertical cylinder side (radius r, axis through c) within [z0, z1].
// `inside` selects the far (inner-surface) hit.
bool HitCylinderSide(const Vector3d& o, const Vector3d& d, const Vector3d& c, double r, double z0,
                     double z1, bool inside, double* t, Vector3d* n) {
  const double ox = o.x() - c.x(), oy = o.y() - c.y();
  const double a = d.x() * d.x() + d.y() * d.y();
  if (a < 1e-12) return false;
  const double b = 2.0 * (ox * d.x() + oy * d.y());
  const double cc = ox * ox + oy * oy - r * r;
  const double disc = b * b - 4.0 * a * cc;
  if (disc < 0.0) return false;
  const double sq = std::sqrt(disc);
  const double candidates[2] = {(-b - sq) / (2.0 * a), (-b + sq) / (2.0 * a)};
  for (int k = inside ? 1 : 0; k < 2; ++k) {
    const double tk = candidates[k];
    if (tk <= 1e-6) continue;
    const double z = o.z() + tk * d.z();
    if (z < z0 || z > z1) continue;
    *t = tk;
    const Vector3d hit = o + tk * d;
    *n = Vector3d(hit.x() - c.x(), hit.y() - c.y(), 0.0).normalized();
    if (inside) *n = -*n;
    return true;
  }
  return false;
}

// Nearest intersection of a ray with a primitive.
bool Intersect(const Primitive& p, const Vector3d& o, const Vector3d& d, double* t, Vector3d* n) {
  switch (p.kind) {
    case PrimitiveKind::kSphere: {
      const Vector3d oc = o - p.center;
      const double b = oc.dot(d);
      const double c = oc.squaredNorm() - p.radius * p.radius;
      const double a = d.squaredNorm();
      const double disc = b * b - a * c;
      if (disc < 0.0) return false;
      const double tt = (-b - std::sqrt(disc)) / a;
      if (tt <= 1e-6) return false;
      *t = tt;
      *n = (o + tt * d - p.center) / p.radius;
      return true;
    }
    case PrimitiveKind::kBox: {
      // Into the box's local frame (yaw about z).
      const double rx = o.x() - p.center.x(), ry = o.y() - p.center.y();
      const Vector3d lo(p.cos_yaw * rx + p.sin_yaw * ry, -p.sin_yaw * rx + p.cos_yaw * ry, o.z());
      const Vector3d ld(p.cos_yaw * d.x() + p.sin_yaw * d.y(),
                        -p.sin_yaw * d.x() + p.cos_yaw * d.y(), d.z());
      const double lo_b[3] = {-p.half_x, -p.half_y, p.z0};
      const double hi_b[3] = {p.half_x, p.half_y, p.z1};
      double t_near = -std::numeric_limits<double>::infinity();
      double t_far = std::numeric_limits<double>::infinity();
      int axis = -1;
      double sign = 1.0;
      for (int i = 0; i < 3; ++i) {
        if (std::abs(ld[i]) < 1e-12) {
          if (lo[i] < lo_b[i] || lo[i] > hi_b[i]) return false;
          continue;
        }
        double t0 = (lo_b[i] - lo[i]) / ld[i];
        double t1 = (hi_b[i] - lo[i]) / ld[i];
        double s = -1.0;
        if (t0 > t1) std::swap(t0, t1), s = 1.0;
        if (t0 > t_near) t_near = t0, axis = i, sign = s;
        t_far = std::min(t_far, t1);
        if (t_near > t_far) return false;
      }
      if (t_near <= 1e-6 || axis < 0) return false;
      *t = t_near;
      Vector3d ln = Vector3d::Zero();
      ln[axis] = sign;
      *n = Vector3d(p.cos_yaw * ln.x() - p.sin_yaw * ln.y(),
                    p.sin_yaw * ln.x() + p.cos_yaw * ln.y(), ln.z());
      return true;
    }
    case PrimitiveKind::kCylinder:
    case PrimitiveKind::kRing: {
      double best = std::numeric_limits<double>::infinity();
      Vector3d best_n = Vector3d::Zero();
      double tt = 0.0;
      Vector3d nn = Vector3d::Zero();
      if (HitCylinderSide(o, d, p.center, p.radius, p.z0, p.z1, false, &tt, &nn) && tt < best)
        best = tt, best_n = nn;
      if (p.kind == PrimitiveKind::kRing &&
          HitCylinderSide(o, d, p.center, p.inner_radius, p.z0, p.z1, true, &tt, &nn) &&
          tt < best) {
        best = tt, best_n = nn;
      }
      // Caps.
      if (std::abs(d.z()) > 1e-12) {
        for (const double zc : {p.z1, p.z0}) {
          tt = (zc - o.z()) / d.z();
          if (tt <= 1e-6 || tt >= best) continue;
          const double dx = o.x() + tt * d.x() - p.center.x();
          const double dy = o.y() + tt * d.y() - p.center.y();
          const double r2 = dx * dx + dy * dy;
          if (r2 > p.radius * p.radius) continue;
          if (p.kind == PrimitiveKind::kRing && r2 < p.inner_radius * p.inner_radius) continue;
          best = tt, best_n = Vector3d(0, 0, zc == p.z1 ? 1.0 : -1.0);
        }
      }
      if (!std::isfinite(best)) return false;
      *t = best;
      *n = best_n;
      return true;
    }
    case PrimitiveKind::kPrism: {
      // A vertical prism over a polygon: the caps where the hit lies inside the outline,
      // the side walls where the ray crosses an edge between z0 and z1.
      const Eigen::Vector2d o2(o.x() - p.center.x(), o.y() - p.center.y());
      const Eigen::Vector2d d2(d.x(), d.y());
      double best = std::numeric_limits<double>::infinity();
      Vector3d best_n = Vector3d::Zero();
      const size_t k = p.polygon.size();
      for (size_t e = 0; e < k; ++e) {
        const Eigen::Vector2d a = p.polygon[e];
        const Eigen::Vector2d edge = p.polygon[(e + 1) % k] - a;
        const double denom = d2.x() * edge.y() - d2.y() * edge.x();
        if (std::abs(denom) < 1e-12) continue;
        const Eigen::Vector2d ao = a - o2;
        const double tt = (ao.x() * edge.y() - ao.y() * edge.x()) / denom;
        const double s = (ao.x() * d2.y() - ao.y() * d2.x()) / denom;
        if (tt <= 1e-6 || tt >= best || s < 0.0 || s > 1.0) continue;
        const double z = o.z() + tt * d.z();
        if (z < p.z0 || z > p.z1) continue;
        best = tt;
        best_n = Vector3d(edge.y(), -edge.x(), 0.0).normalized();  // outward (CCW outline)
      }
      if (std::abs(d.z()) > 1e-12) {
        for (const double zc : {p.z1, p.z0}) {
          const double tt = (zc - o.z()) / d.z();
          if (tt <= 1e-6 || tt >= best) continue;
          const Eigen::Vector2d q = o2 + tt * d2;
          bool inside = false;  // crossing number
          for (size_t e = 0, f = k - 1; e < k; f = e++) {
            const Eigen::Vector2d& a = p.polygon[e];
            const Eigen::Vector2d& b = p.polygon[f];
            if ((a.y() > q.y()) != (b.y() > q.y()) &&
                q.x() < (b.x() - a.x()) * (q.y() - a.y()) / (b.y() - a.y()) + a.x()) {
              inside = !inside;
            }
          }
          if (inside) best = tt, best_n = Vector3d(0, 0, zc == p.z1 ? 1.0 : -1.0);
        }
      }
      if (!std::isfinite(best)) return false;
      *t = best;
      *n = best_n;
      return true;
    }
    case PrimitiveKind::kPlate: {
      const double denom = p.plate_normal.dot(d);
      if (std::abs(denom) < 1e-9) return false;
      const double tt = p.plate_normal.dot(p.center - o) / denom;
      if (tt <= 1e-6) return false;
      const Vector3d hit = o + tt * d;
      const Vector3d rel = hit - p.center;
      if (p.plate_disc) {
        if (rel.squaredNorm() > p.radius * p.radius) return false;
      } else {
        const Vector3d side = Vector3d::UnitZ().cross(p.plate_normal);
        if (std::abs(rel.dot(side)) > p.half_x || std::abs(rel.z()) > p.half_x) return false;
      }
      *t = tt;
      *n = denom < 0 ? p.plate_normal : -p.plate_normal;
      return true;
    }
  }
  return false;
}

// Intersect() for a cylinder or ring, two rays at a time: the same double operations in the
// same order, so the same hits, depths and normals bit for bit. `hit` is Intersect's result
// and `t` < `t_old`.
struct Hit2 {
  M2 hit;
  D2 t, nx, ny, nz;
};
inline SLAMO_ALWAYS_INLINE Hit2 IntersectCylinder2(const Primitive& p, const Vector3d& o, D2 dx,
                                                   D2 dy, D2 dz, D2 t_old) {
  const double inf = std::numeric_limits<double>::infinity();
  const M2 none{_mm_setzero_pd()};
  // Rays whose line passes the axis farther than the (outer) radius, by a margin of 1e-6 that
  // is orders of magnitude above the rounding of either test, meet neither the side (their
  // discriminant is negative) nor a cap (no point of the line is within the radius): when
  // both rays do, Intersect() says no for both and nothing else need be computed. Squared
  // distance from the axis: ((o - c) x d)^2 / |d|^2 in the plane; near-vertical rays (|d|^2
  // in the plane below 1e-9) are left to the full test.
  {
    const double ox = o.x() - p.center.x(), oy = o.y() - p.center.y();
    const D2 a = dx * dx + dy * dy;
    const D2 cross = D2(ox) * dy - D2(oy) * dx;
    const M2 away = (a > D2(1e-9)) & (cross * cross > D2(p.radius * p.radius * (1.0 + 1e-6)) * a);
    if (_mm_movemask_pd(away.m) == 3) return {none, 0.0, 0.0, 0.0, 0.0};
  }
  // HitCylinderSide: radius r, the far (inner) candidate only when `inside`.
  const auto side = [&](double r, bool inside) {
    const double ox = o.x() - p.center.x(), oy = o.y() - p.center.y();
    const D2 a = dx * dx + dy * dy;
    const D2 b = D2(2.0) * (D2(ox) * dx + D2(oy) * dy);
    const double cc = ox * ox + oy * oy - r * r;
    const D2 disc = b * b - D2(4.0) * a * D2(cc);
    const D2 sq = Sqrt(disc);
    const D2 candidates[2] = {(-b - sq) / (D2(2.0) * a), (-b + sq) / (D2(2.0) * a)};
    M2 ok[2];
    for (int k = 0; k < 2; ++k) {
      const D2 z = D2(o.z()) + candidates[k] * dz;
      ok[k] = NotLessEqual(candidates[k], 1e-6) & NotLess(z, p.z0) & NotGreater(z, p.z1);
    }
    if (inside) ok[0] = none;
    Hit2 h;
    h.hit = NotLess(a, 1e-12) & NotLess(disc, 0.0) & (ok[0] | ok[1]);
    h.t = Select(ok[0], candidates[0], candidates[1]);
    // (hit - c, 0).normalized(): |.|^2 = hx^2 + (hy^2 + 0^2) = hx^2 + hy^2.
    const D2 hx = D2(o.x()) + h.t * dx - D2(p.center.x());
    const D2 hy = D2(o.y()) + h.t * dy - D2(p.center.y());
    const D2 n2 = hx * hx + hy * hy;
    const D2 n = Sqrt(n2);
    const M2 positive = n2 > D2(0.0);
    h.nx = Select(positive, hx / n, hx), h.ny = Select(positive, hy / n, hy), h.nz = 0.0;
    if (inside) h.nx = -h.nx, h.ny = -h.ny, h.nz = -h.nz;
    return h;
  };
  D2 best = inf, best_nx = 0.0, best_ny = 0.0, best_nz = 0.0;
  const auto take = [&](M2 better, D2 t, D2 nx, D2 ny, D2 nz) {
    best = Select(better, t, best), best_nx = Select(better, nx, best_nx);
    best_ny = Select(better, ny, best_ny), best_nz = Select(better, nz, best_nz);
  };
  const Hit2 outer = side(p.radius, false);
  take(outer.hit & (outer.t < best), outer.t, outer.nx, outer.ny, outer.nz);
  if (p.kind == PrimitiveKind::kRing) {
    const Hit2 inner = side(p.inner_radius, true);
    take(inner.hit & (inner.t < best), inner.t, inner.nx, inner.ny, inner.nz);
  }
  // Caps, where |d.z| > 1e-12.
  const M2 not_flat{_mm_cmpgt_pd(_mm_andnot_pd(_mm_set1_pd(-0.0), dz.m), _mm_set1_pd(1e-12))};
  for (const double zc : {p.z1, p.z0}) {
    // tt = (zc - o.z) / d.z is positive only where d.z has the sign of zc - o.z; elsewhere it
    // is <= 0 and the cap is not taken, so a pair of rays that both head away skips it.
    const double rise = zc - o.z();
    const M2 toward{rise > 0.0   ? _mm_cmpgt_pd(dz.m, _mm_setzero_pd())
                    : rise < 0.0 ? _mm_cmplt_pd(dz.m, _mm_setzero_pd())
                                 : _mm_setzero_pd()};
    if (!_mm_movemask_pd((not_flat & toward).m)) continue;
    const D2 tt = (D2(zc) - D2(o.z())) / dz;
    const D2 cx = D2(o.x()) + tt * dx - D2(p.center.x());
    const D2 cy = D2(o.y()) + tt * dy - D2(p.center.y());
    const D2 r2 = cx * cx + cy * cy;
    M2 inside = not_flat & NotLessEqual(tt, 1e-6) & NotGreaterEqual(tt, best) &
                NotGreater(r2, p.radius * p.radius);
    if (p.kind == PrimitiveKind::kRing)
      inside = inside & NotLess(r2, p.inner_radius * p.inner_radius);
    take(inside, tt, 0.0, 0.0, zc == p.z1 ? 1.0 : -1.0);
  }
  return {IsFinite(best) & (best < t_old), best, best_nx, best_ny, best_nz};
}

Primitive ObjectPrimitive(const field::SeasonConfig& season, const SimObject& object) {
  const field::ObjectType& type = *object.type;
  Primitive p;
  p.id = object.id;
  p.albedo = Albedo(season, object.colour);
  p.opacity = type.material == field::Material::kSemiTransparent ? type.opacity : 1.0;
  p.center = object.center_m;
  const double half_h = type.height_m / 2.0;
  p.z0 = object.center_m.z() - half_h;
  p.z1 = object.center_m.z() + half_h;
  switch (type.shape) {
    case field::ObjectShape::kSphere:
    case field::ObjectShape::kTriball:  // rendered as its bounding sphere
      p.kind = PrimitiveKind::kSphere;
      p.radius = type.size_m / 2.0;
      p.glossy = true;
      break;
    case field::ObjectShape::kCube:
    case field::ObjectShape::kHollowBlock:
      p.kind = PrimitiveKind::kBox;
      p.half_x = p.half_y = type.size_m / 2.0;
      break;
    case field::ObjectShape::kTorus:  // a flat ring: outer diameter size_m, tube = height
      p.kind = PrimitiveKind::kRing;
      p.radius = type.size_m / 2.0;
      p.inner_radius = std::max(0.0, p.radius - std::max(type.height_m, type.size_m * 0.2));
      break;
    case field::ObjectShape::kStar:  // a five-pointed star prism, lying flat
      p.kind = PrimitiveKind::kPrism;
      p.radius = type.size_m / 2.0;
      for (int k = 0; k < 10; ++k) {
        const double angle = kPi / 2.0 + k * kPi / 5.0;
        const double r = k % 2 == 0 ? p.radius : 0.45 * p.radius;
        p.polygon.emplace_back(r * std::cos(angle), r * std::sin(angle));
      }
      break;
    case field::ObjectShape::kCylinder:
      p.kind = PrimitiveKind::kCylinder;
      p.radius = type.size_m / 2.0;
      break;
  }
  SetAabb(&p);
  return p;
}

// An opponent in arena mode, from its footprint box `body`: a dark metal chassis, bumpers in
// the alliance's colour all round its foot, and an alliance-coloured flag plate on top.
void AddArenaRobot(const field::SeasonConfig& season, const Primitive& body, const char* alliance,
                   std::vector<Primitive>* out) {
  const Vector3d team =
      season.colours.count(alliance) ? Albedo(season, alliance) : Vector3d(Vector3d::Constant(0.5));
  Primitive chassis = body;
  chassis.albedo = Vector3d(0.22, 0.22, 0.24);
  chassis.glossy = true;
  SetAabb(&chassis);
  out->push_back(chassis);
  constexpr double kBumper = 0.06;  // thickness (m)
  for (int side = 0; side < 4; ++side) {
    Primitive bumper = body;
    const bool along_x = side < 2;
    const double sign = side % 2 ? -1.0 : 1.0;
    const double offset = (along_x ? body.half_y : body.half_x) + kBumper / 2.0;
    const Vector3d local = along_x ? Vector3d(0, sign * offset, 0) : Vector3d(sign * offset, 0, 0);
    bumper.center = body.center + Vector3d(body.cos_yaw * local.x() - body.sin_yaw * local.y(),
                                           body.sin_yaw * local.x() + body.cos_yaw * local.y(), 0);
    bumper.half_x = along_x ? body.half_x + kBumper : kBumper / 2.0;
    bumper.half_y = along_x ? kBumper / 2.0 : body.half_y;
    bumper.z0 = 0.02;
    bumper.z1 = 0.14;
    bumper.albedo = team;
    SetAabb(&bumper);
    out->push_back(bumper);
  }
  Primitive flag = body;
  flag.half_x = 0.01;
  flag.half_y = std::min(0.12, body.half_y);
  flag.z0 = body.z1;
  flag.z1 = body.z1 + 0.15;
  flag.albedo = team;
  SetAabb(&flag);
  out->push_back(flag);
}

}  // namespace

struct SimRenderer::Buffers {
  int width = 0, height = 0;
  std::vector<float> t;          // depth along the optical axis (m), inf = nothing
  std::vector<Vector3f> colour;  // linear RGB in [0, 1]
  std::vector<uint16_t> id;
  std::vector<uint8_t> no_depth;   // 1: the camera reads nothing here (black, specular, sky)
  std::vector<Vector3f> row_rays;  // per row, the world ray of its first pixel (camera z = 1)

  void Reset(int w, int h) {
    width = w, height = h;
    const size_t n = static_cast<size_t>(w) * h;
    // Kept between frames: resizing is a no-op after the first, so no fresh pages per frame.
    // kPad pixels more than the image: the passes work on four pixels at a time.
    t.resize(n + kPad), colour.resize(n + kPad), id.resize(n + kPad), no_depth.resize(n + kPad);
    row_rays.resize(h);
    // t, colour and no_depth are written for every pixel by the floor pass.
    std::fill(id.begin(), id.begin() + n, uint16_t{0});
  }
};

SimRenderer::SimRenderer(const field::SeasonConfig& season, const field::CameraConfig& camera,
                         RenderOptions options, uint64_t seed)
    : season_(season),
      camera_(camera),
      options_(options),
      seed_(seed),
      rng_(seed),
      depth_buffers_(std::make_unique<Buffers>()),
      colour_buffers_(std::make_unique<Buffers>()) {
  rays_cam_.reserve(static_cast<size_t>(camera.width_px) * camera.height_px);
  ray_length2_.reserve(rays_cam_.capacity());
  for (int v = 0; v < camera.height_px; ++v) {
    for (int u = 0; u < camera.width_px; ++u) {
      rays_cam_.emplace_back(static_cast<float>((u + 0.5 - camera.cx) / camera.fx),
                             static_cast<float>((v + 0.5 - camera.cy) / camera.fy), 1.0f);
      ray_length2_.push_back(rays_cam_.back().squaredNorm());
    }
  }
  ray_length2_.resize(ray_length2_.size() + kPad, 1.0f);  // read four pixels at a time (kPad)
  BuildStaticPrimitives();
  // sigma(d) per millimetre of depth, so the per-pixel noise needs no table search.
  sigma_mm_by_mm_.resize(static_cast<size_t>(camera.max_range_m * 1000.0) + 2);
  for (size_t mm = 0; mm < sigma_mm_by_mm_.size(); ++mm) {
    sigma_mm_by_mm_[mm] = static_cast<float>(1000.0 * DepthSigmaM((mm + 0.5) / 1000.0));
  }
}

SimRenderer::~SimRenderer() = default;

void SimRenderer::FillNormalPool() {
  // A pool of standard normal draws, read from a random offset each frame: per-pixel noise
  // without a normal draw per pixel per frame. The pool holds four frames' worth of pixels
  // (at least 2^20), so a frame's colour noise (3 per pixel) always fits after an offset.
  std::normal_distribution<float> normal(0.0f, 1.0f);
  normal_pool_.resize(std::max<size_t>(size_t{1} << 20, 4 * rays_cam_.size()));
  for (float& x : normal_pool_) x = normal(rng_);
}

void SimRenderer::BuildStaticPrimitives() {
  for (const field::Structure& s : season_.structures) {
    Primitive p;
    p.center = Vector3d(s.center_m.x, s.center_m.y, 0.0);
    p.z0 = s.z_min_m;
    p.z1 = s.height_m;
    p.albedo = Albedo(season_, s.colour);
    if (s.shape == field::SolidShape::kBox) {
      p.kind = PrimitiveKind::kBox;
      p.half_x = s.size_m.x / 2.0;
      p.half_y = s.size_m.y / 2.0;
      p.cos_yaw = std::cos(s.yaw_deg * kPi / 180.0);
      p.sin_yaw = std::sin(s.yaw_deg * kPi / 180.0);
    } else {
      p.kind = PrimitiveKind::kCylinder;
      p.radius = s.radius_m;
    }
    SetAabb(&p);
    static_primitives_.push_back(p);
  }
  // Landmarks: discs and squares are plates on the inner face of the nearest wall, facing the
  // field; cylinders and spheres stand where they are.
  for (size_t i = 0; i < season_.landmarks.size(); ++i) {
    const field::Landmark& l = season_.landmarks[i];
    Primitive p;
    p.id = kLandmarkIdBase + static_cast<int>(i);
    p.albedo = Albedo(season_, l.colour);
    const double r = l.size_m / 2.0;
    p.z0 = l.height_m - r;
    p.z1 = l.height_m + r;
    if (l.shape == field::LandmarkShape::kDisc || l.shape == field::LandmarkShape::kSquare) {
      p.kind = PrimitiveKind::kPlate;
      p.plate_disc = l.shape == field::LandmarkShape::kDisc;
      p.radius = r;
      p.half_x = r;
      const bool on_x_wall = std::abs(l.position_m.x) >= std::abs(l.position_m.y);
      p.center = LandmarkCentre(season_, l);
      p.plate_normal = on_x_wall ? Vector3d(p.center.x() > 0 ? -1.0 : 1.0, 0.0, 0.0)
                                 : Vector3d(0.0, p.center.y() > 0 ? -1.0 : 1.0, 0.0);
    } else if (l.shape == field::LandmarkShape::kCylinder) {
      p.kind = PrimitiveKind::kCylinder;
      p.radius = r;
      p.center = LandmarkCentre(season_, l);
    } else {
      p.kind = PrimitiveKind::kSphere;
      p.radius = r;
      p.center = LandmarkCentre(season_, l);
    }
    SetAabb(&p);
    landmark_centres_.push_back(p.center);
    static_primitives_.push_back(p);
  }
}

Eigen::Isometry3d SimRenderer::CameraPose(const Pose2D& robot) const {
  return WorldFromRobot(robot) * RobotFromCamera(camera_.mount);
}

double SimRenderer::DepthSigmaM(double depth_m) const {
  return platform::DepthSigmaM(camera_, depth_m);
}

SLAMO_AVX_CLONES void SimRenderer::RenderPass(const SimWorld& world,
                                              const Eigen::Isometry3d& world_from_camera,
                                              const ArenaBackdrop* arena, Buffers* out) const {
  const int w = camera_.width_px;
  const int h = camera_.height_px;
  out->Reset(w, h);
  const Eigen::Matrix3f rotation = world_from_camera.linear().cast<float>();
  const Vector3d origin = world_from_camera.translation();
  const Lighting& light = world.lighting;
  const double half = season_.HalfSize();
  const double wall_h = season_.field.wall_height_m;
  const Vector3d tile_albedo = Albedo(season_, season_.field.tile_colour);
  const Vector3d wall_albedo = Albedo(season_, season_.field.wall_colour);
  const double tile = season_.field.tile_m;

  const Vector3f to_light_f = light.to_light.cast<float>();
  const Vector3f tint_f = light.tint.cast<float>();
  const float ambient_f = static_cast<float>(light.ambient);
  const float diffuse_f = static_cast<float>(light.diffuse);
  // Lambert: albedo * (ambient + diffuse * max(0, n . l)) * tint.
  const auto shade_f = [&](const Vector3f& albedo, const Vector3f& n) -> Vector3f {
    const float lambert = ambient_f + diffuse_f * std::max(0.0f, n.dot(to_light_f));
    return albedo.cwiseProduct(tint_f) * lambert;
  };
  const auto shade = [&](const Vector3d& albedo, const Vector3d& n) -> Vector3f {
    return shade_f(albedo.cast<float>(), n.cast<float>());
  };

  // 1. Floor, walls and the venue beyond them, for every pixel; the world rays are kept for
  // the passes below. Single precision and per-frame constants: this loop touches every pixel.
  std::vector<Vector3f>& row_rays = out->row_rays;
  const Vector3f o = origin.cast<float>();
  const float half_f = static_cast<float>(half);
  const float tile_f = static_cast<float>(tile);
  const float wall_h_f = static_cast<float>(wall_h);
  const Vector3f floor_colour = shade(tile_albedo, Vector3d::UnitZ());
  const Vector3f wall_colour[4] = {
      shade(wall_albedo, -Vector3d::UnitX()), shade(wall_albedo, Vector3d::UnitX()),
      shade(wall_albedo, -Vector3d::UnitY()), shade(wall_albedo, Vector3d::UnitY())};
  const bool floor_black = Luminance(tile_albedo) < options_.black_albedo;
  const bool wall_black = Luminance(wall_albedo) < options_.black_albedo;
  constexpr float kSeamM = 0.004f;
  // The world ray is linear in u along a row: start of row plus u steps.
  const Vector3f ray_step = rotation.col(0) / static_cast<float>(camera_.fx);
  // Four pixels at a time in SSE2: the same single-precision operations in the same order as
  // one pixel at a time (no FMA), so the same bits. The row's rays are accumulated first.
  const int w4 = (w + 3) / 4 * 4;
  // Four rows' rays at a time, one array of w4 per row.
  std::vector<float> rays_x(4 * w4), rays_y(4 * w4), rays_z(4 * w4);
  const F4 step_x(ray_step.x()), step_y(ray_step.y()), step_z(ray_step.z());
  const F4 ox(o.x()), oy(o.y()), oz(o.z()), neg_oz(-o.z());
  const F4 half4(half_f), field4(2.0f * half_f), tile4(tile_f), zero(0.0f), inf(kInf);
  const F4 seam_lo(kSeamM), seam_hi(tile_f - kSeamM);
  // The walls' planes as seen from the camera: x = +half (0), -half (1), y = +half (2), -half (3).
  const F4 to_wall_x[2] = {half_f - o.x(), -half_f - o.x()};
  const F4 to_wall_y[2] = {half_f - o.y(), -half_f - o.y()};
  const __m128i hash_x = _mm_set1_epi32(73856093), hash_y = _mm_set1_epi32(19349663);
  const M4 floor_black4 = {_mm_castsi128_ps(_mm_set1_epi32(floor_black ? -1 : 0))};
  const M4 wall_black4 = {_mm_castsi128_ps(_mm_set1_epi32(wall_black ? -1 : 0))};
  const M4 all_lanes = {_mm_castsi128_ps(_mm_set1_epi32(-1))};
  const __m128 floor_rgbr =
      _mm_setr_ps(floor_colour.x(), floor_colour.y(), floor_colour.z(), floor_colour.x());
  const __m128 floor_gbrg =
      _mm_setr_ps(floor_colour.y(), floor_colour.z(), floor_colour.x(), floor_colour.y());
  const __m128 floor_brgb =
      _mm_setr_ps(floor_colour.z(), floor_colour.x(), floor_colour.y(), floor_colour.z());
  const int floor_flags = floor_black ? 0x01010101 : 0;
  for (int v0 = 0; v0 < h; v0 += 4) {
    // The rays of four rows: each row's first ray, then u steps added one after another as
    // one pixel at a time did, the four rows side by side in the lanes (four independent
    // chains of additions instead of one), four steps at a time transposed into the rows.
    const int rows = std::min(4, h - v0);
    alignas(16) float first_x[4] = {}, first_y[4] = {}, first_z[4] = {};
    for (int k = 0; k < rows; ++k) {
      const Vector3f d = rotation * rays_cam_[static_cast<size_t>(v0 + k) * w];
      row_rays[v0 + k] = d;
      first_x[k] = d.x(), first_y[k] = d.y(), first_z[k] = d.z();
    }
    F4 ray4[3] = {F4(_mm_load_ps(first_x)), F4(_mm_load_ps(first_y)), F4(_mm_load_ps(first_z))};
    const F4 steps[3] = {step_x, step_y, step_z};
    float* const rays[3] = {rays_x.data(), rays_y.data(), rays_z.data()};
    for (int u0 = 0; u0 < w4; u0 += 4) {
      for (int c = 0; c < 3; ++c) {
        __m128 s0 = ray4[c].m;
        ray4[c] = ray4[c] + steps[c];
        __m128 s1 = ray4[c].m;
        ray4[c] = ray4[c] + steps[c];
        __m128 s2 = ray4[c].m;
        ray4[c] = ray4[c] + steps[c];
        __m128 s3 = ray4[c].m;
        ray4[c] = ray4[c] + steps[c];
        _MM_TRANSPOSE4_PS(s0, s1, s2, s3);
        _mm_storeu_ps(rays[c] + u0, s0), _mm_storeu_ps(rays[c] + w4 + u0, s1);
        _mm_storeu_ps(rays[c] + 2 * w4 + u0, s2), _mm_storeu_ps(rays[c] + 3 * w4 + u0, s3);
      }
    }
    for (int v = v0; v < v0 + rows; ++v) {
      const float* row_x = rays_x.data() + (v - v0) * w4;
      const float* row_y = rays_y.data() + (v - v0) * w4;
      const float* row_z = rays_z.data() + (v - v0) * w4;
      for (int u0 = 0; u0 < w; u0 += 4) {
        const size_t i = static_cast<size_t>(v) * w + u0;
        const F4 dx = Load4(&row_x[u0]), dy = Load4(&row_y[u0]), dz = Load4(&row_z[u0]);
        const F4 t_floor = neg_oz / dz;
        const F4 px = ox + t_floor * dx + half4, py = oy + t_floor * dy + half4;
        // A floor point inside the perimeter is reached before any wall (the camera is inside
        // the field), so the walls only matter for rays that miss the field's floor.
        const M4 on_floor =
            (dz < F4(-1e-9f)) & (px >= zero) & (py >= zero) & (px <= field4) & (py <= field4);
        const int floor_lanes = Bits(on_floor);
        F4 r = zero, g = zero, b = zero, t = zero;
        M4 no_depth = floor_black4, wall_or_floor = on_floor;
        if (floor_lanes) {
          // Tiles: seams 4 mm wide, each tile's shade varied a little by its hash's low byte
          // (which only the products' low 16 bits decide).
          const F4 fx = px / tile4, fy = py / tile4;
          const __m128i ix = _mm_cvttps_epi32(fx.m), iy = _mm_cvttps_epi32(fy.m);
          const F4 sx = (fx - F4(_mm_cvtepi32_ps(ix))) * tile4;
          const F4 sy = (fy - F4(_mm_cvtepi32_ps(iy))) * tile4;
          const M4 seam = (sx < seam_lo) | (sy < seam_lo) | (sx > seam_hi) | (sy > seam_hi);
          const __m128i hash =
              _mm_and_si128(_mm_xor_si128(_mm_mullo_epi16(ix, hash_x), _mm_mullo_epi16(iy, hash_y)),
                            _mm_set1_epi32(0xff));
          const F4 variation = F4(0.96f) + F4(0.08f) * (F4(_mm_cvtepi32_ps(hash)) / F4(255.0f));
          const F4 shade = Select(seam, 0.7f, variation);
          if (floor_lanes == 0xf) {
            // All floor: floor_colour * shade straight into RGB order, (r g b r) * (s0 s0 s0 s1)
            // and so on.
            const __m128 s0 = _mm_shuffle_ps(shade.m, shade.m, _MM_SHUFFLE(1, 0, 0, 0));
            const __m128 s1 = _mm_shuffle_ps(shade.m, shade.m, _MM_SHUFFLE(2, 2, 1, 1));
            const __m128 s2 = _mm_shuffle_ps(shade.m, shade.m, _MM_SHUFFLE(3, 3, 3, 2));
            float* colour = out->colour[i].data();
            _mm_storeu_ps(colour, _mm_mul_ps(floor_rgbr, s0));
            _mm_storeu_ps(colour + 4, _mm_mul_ps(floor_gbrg, s1));
            _mm_storeu_ps(colour + 8, _mm_mul_ps(floor_brgb, s2));
            _mm_storeu_ps(&out->t[i], t_floor.m);
            std::memcpy(&out->no_depth[i], &floor_flags, 4);
            continue;
          }
          r = F4(floor_colour.x()) * shade, g = F4(floor_colour.y()) * shade;
          b = F4(floor_colour.z()) * shade, t = t_floor;
        }
        if (floor_lanes != 0xf) {
          // The nearest perimeter wall along the ray, then the venue above the walls.
          const M4 pos_x = dx > F4(1e-9f), neg_x = dx < F4(-1e-9f);
          const M4 pos_y = dy > F4(1e-9f), neg_y = dy < F4(-1e-9f);
          const F4 t_x = Select(pos_x | neg_x, Select(pos_x, to_wall_x[0], to_wall_x[1]) / dx, inf);
          const F4 t_y = Select(pos_y, to_wall_y[0], to_wall_y[1]) / dy;
          const M4 use_y = (pos_y | neg_y) & (t_y < t_x);
          const F4 t_wall = Select(use_y, t_y, t_x);
          const M4 on_wall = AndNot((t_wall < inf) & (oz + t_wall * dz <= F4(wall_h_f)), on_floor);
          const auto wall_channel = [&](int c) {
            return Select(use_y, Select(pos_y, wall_colour[2][c], wall_colour[3][c]),
                          Select(pos_x, wall_colour[0][c], wall_colour[1][c]));
          };
          // The venue: dim, no depth within the camera's range.
          const F4 gray = F4(0.25f) + F4(0.1f) * MaxZero(dz / Sqrt(dx * dx + (dy * dy + dz * dz)));
          const F4 venue_b = gray * F4(1.1f);
          wall_or_floor = on_floor | on_wall;
          if (!Bits(wall_or_floor)) {  // all venue
            r = g = gray, b = venue_b, t = inf, no_depth = all_lanes;
          } else {
            r = Select(on_floor, r, Select(on_wall, wall_channel(0), gray));
            g = Select(on_floor, g, Select(on_wall, wall_channel(1), gray));
            b = Select(on_floor, b, Select(on_wall, wall_channel(2), venue_b));
            t = Select(on_floor, t, Select(on_wall, t_wall, inf));
            no_depth = Select(on_floor, floor_black4, Select(on_wall, wall_black4, all_lanes));
          }
        }
        StoreRgb4(&out->colour[i], r, g, b);
        _mm_storeu_ps(&out->t[i], t.m);
        const __m128i flags16 = _mm_packs_epi32(_mm_castps_si128(no_depth.m), _mm_setzero_si128());
        const int flags = _mm_cvtsi128_si32(
            _mm_and_si128(_mm_packs_epi16(flags16, _mm_setzero_si128()), _mm_set1_epi8(1)));
        std::memcpy(&out->no_depth[i], &flags, 4);
        const int other_lanes = ~Bits(wall_or_floor) & 0xf;
        if (arena && other_lanes) {
          for (int lane = 0; lane < 4 && u0 + lane < w; ++lane) {
            if (!(other_lanes >> lane & 1)) continue;
            const Vector3f d(row_x[u0 + lane], row_y[u0 + lane], row_z[u0 + lane]);
            ShadeArena(*arena, o, d, &out->colour[i + lane], &out->t[i + lane],
                       &out->no_depth[i + lane]);
          }
        }
      }
    }
  }

  // 2. Solid primitives, each over its projected bounding box only.
  std::vector<Primitive> primitives = static_primitives_;
  std::vector<Primitive> transparent;
  for (size_t k = 0; k < world.opponents.size(); ++k) {
    const SimOpponent& o = world.opponents[k];
    Primitive p;
    p.kind = PrimitiveKind::kBox;
    p.id = kOpponentIdBase + static_cast<int>(k);
    p.center = Vector3d(o.pose.x_m, o.pose.y_m, 0.0);
    p.half_x = o.config.size_m.x / 2.0;
    p.half_y = o.config.size_m.y / 2.0;
    p.z0 = 0.0;
    p.z1 = o.height_m;
    p.cos_yaw = std::cos(o.pose.theta_rad);
    p.sin_yaw = std::sin(o.pose.theta_rad);
    const char* alliance = field::ToString(o.config.alliance);
    if (arena) {
      AddArenaRobot(season_, p, alliance, &primitives);
      continue;
    }
    p.albedo = season_.colours.count(alliance) ? Vector3d(0.6 * Albedo(season_, alliance))
                                               : Vector3d(Vector3d::Constant(0.3));
    SetAabb(&p);
    primitives.push_back(p);
  }
  for (const SimObject& object : world.objects) {
    if (object.held) continue;
    Primitive p = ObjectPrimitive(season_, object);
    (p.opacity < 1.0 ? transparent : primitives).push_back(p);
  }
  const Eigen::Isometry3d camera_from_world = world_from_camera.inverse();
  // A primitive's pixels lie inside the projection of its bounding box. The box's corners are
  // taken into the camera frame and their camera-space bounds clipped at the near plane, so a
  // box that straddles the camera plane still gets a tight screen box.
  const auto screen_box = [&](const Primitive& p) {
    constexpr double kNear = 0.02;
    Vector3d lo = Vector3d::Constant(std::numeric_limits<double>::infinity());
    Vector3d hi = -lo;
    for (int k = 0; k < 8; ++k) {
      const Vector3d corner((k & 1) ? p.aabb_max.x() : p.aabb_min.x(),
                            (k & 2) ? p.aabb_max.y() : p.aabb_min.y(),
                            (k & 4) ? p.aabb_max.z() : p.aabb_min.z());
      const Vector3d c = camera_from_world * corner;
      lo = lo.cwiseMin(c), hi = hi.cwiseMax(c);
    }
    if (hi.z() < kNear) return cv::Rect();  // wholly behind the camera
    const double z_near = std::max(lo.z(), kNear);
    // x / z over the clipped box is extreme at its corners.
    const auto range = [&](double a, double b, double f, double centre, double* out_lo,
                           double* out_hi) {
      const double values[4] = {a / z_near, a / hi.z(), b / z_near, b / hi.z()};
      *out_lo = f * *std::min_element(values, values + 4) + centre;
      *out_hi = f * *std::max_element(values, values + 4) + centre;
    };
    double u0, u1, v0, v1;
    range(lo.x(), hi.x(), camera_.fx, camera_.cx, &u0, &u1);
    range(lo.y(), hi.y(), camera_.fy, camera_.cy, &v0, &v1);
    const int iu0 = static_cast<int>(std::max(0.0, std::floor(u0)));
    const int iv0 = static_cast<int>(std::max(0.0, std::floor(v0)));
    const int iu1 = static_cast<int>(std::min(w - 1.0, std::ceil(u1)));
    const int iv1 = static_cast<int>(std::min(h - 1.0, std::ceil(v1)));
    if (iu1 < iu0 || iv1 < iv0) return cv::Rect();
    return cv::Rect(iu0, iv0, iu1 - iu0 + 1, iv1 - iv0 + 1);
  };
  // Calls on_hit(first pixel, lanes, rays, t, normals) for four pixels of a row at a time, the
  // lanes set where `p` is the nearest surface so far. The buffers hold kPad pixels beyond
  // the last, so a row's last group may read and write past its end (its lanes stay clear).
  const F4 lane_offsets(_mm_set_ps(3.0f, 2.0f, 1.0f, 0.0f));
  const auto for_each_hit = [&](const Primitive& p, auto&& on_hit) SLAMO_ALWAYS_INLINE {
    const cv::Rect box = screen_box(p);
    const int u_end = box.x + box.width;
    const auto for_each_group = [&](auto&& group) SLAMO_ALWAYS_INLINE {
      for (int v = box.y; v < box.y + box.height; ++v) {
        const F4 row_x(row_rays[v].x()), row_y(row_rays[v].y()), row_z(row_rays[v].z());
        for (int u0 = box.x; u0 < u_end; u0 += 4) {
          const F4 u = F4(static_cast<float>(u0)) + lane_offsets;  // exact: small integers
          // The ray as one pixel at a time: start of row plus u steps.
          const V3 d{row_x + u * step_x, row_y + u * step_y, row_z + u * step_z};
          group(static_cast<size_t>(v) * w + u0, u < F4(static_cast<float>(u_end)), d);
        }
      }
    };
    if (p.kind == PrimitiveKind::kSphere) {
      // Spheres, the most common object, in single precision: |d|^2 is the camera ray's
      // (rotation keeps lengths), so a hit costs a dot product and a square root.
      const Vector3f oc_f = (origin - p.center).cast<float>();
      const V3 oc{oc_f.x(), oc_f.y(), oc_f.z()};
      const F4 c = oc_f.squaredNorm() - static_cast<float>(p.radius * p.radius);
      const F4 inv_r = static_cast<float>(1.0 / p.radius);
      for_each_group([&](size_t i, M4 lanes, const V3& d) SLAMO_ALWAYS_INLINE {
        const F4 b = Dot(oc, d);
        const F4 a = Load4(&ray_length2_[i]);
        const F4 disc = b * b - a * c;
        const M4 meets = lanes & NotLess(disc, 0.0f);
        if (!Bits(meets)) return;  // no square root or division for groups beside the sphere
        const F4 t = (-b - Sqrt(disc)) / a;
        const M4 hit = meets & NotLessEqual(t, 1e-6f) & NotGreaterEqual(t, Load4(&out->t[i]));
        if (!Bits(hit)) return;
        on_hit(i, hit, d, t,
               V3{(oc.x + t * d.x) * inv_r, (oc.y + t * d.y) * inv_r, (oc.z + t * d.z) * inv_r});
      });
      return;
    }
    if (p.kind == PrimitiveKind::kBox) {
      // Boxes (structures, cubes, opponents) in single precision, in the box's own frame.
      const F4 cy = static_cast<float>(p.cos_yaw), sy = static_cast<float>(p.sin_yaw);
      const F4 neg_sy = -static_cast<float>(p.sin_yaw);
      const float rx = static_cast<float>(origin.x() - p.center.x());
      const float ry = static_cast<float>(origin.y() - p.center.y());
      const float cy_f = static_cast<float>(p.cos_yaw), sy_f = static_cast<float>(p.sin_yaw);
      const F4 lo_o[3] = {cy_f * rx + sy_f * ry, -sy_f * rx + cy_f * ry,
                          static_cast<float>(origin.z())};
      const F4 lo_b[3] = {static_cast<float>(-p.half_x), static_cast<float>(-p.half_y),
                          static_cast<float>(p.z0)};
      const F4 hi_b[3] = {static_cast<float>(p.half_x), static_cast<float>(p.half_y),
                          static_cast<float>(p.z1)};
      const F4 zero(0.0f), one(1.0f), minus_one(-1.0f);
      for_each_group([&](size_t i, M4 lanes, const V3& d) SLAMO_ALWAYS_INLINE {
        const F4 ld[3] = {cy * d.x + sy * d.y, neg_sy * d.x + cy * d.y, d.z};
        F4 t_near = -kInf, t_far = kInf;
        // The slab test per axis; a lane that misses on one axis stops there, one pixel at a
        // time, so its miss is kept whatever the later axes say.
        M4 miss{_mm_setzero_ps()}, has_axis{_mm_setzero_ps()};
        F4 lx = zero, ly = zero, lz = zero;  // the entry face's local normal
        for (int k = 0; k < 3; ++k) {
          const M4 parallel = F4(_mm_andnot_ps(_mm_set1_ps(-0.0f), ld[k].m)) < F4(1e-12f);
          const M4 outside = (lo_o[k] < lo_b[k]) | (lo_o[k] > hi_b[k]);
          const F4 inv = one / ld[k];
          const F4 t0 = (lo_b[k] - lo_o[k]) * inv, t1 = (hi_b[k] - lo_o[k]) * inv;
          const M4 swap = t0 > t1;
          const F4 near_k = Select(swap, t1, t0), far_k = Select(swap, t0, t1);
          const F4 sign = Select(swap, one, minus_one);
          const M4 enter = AndNot(near_k > t_near, parallel);
          t_near = Select(enter, near_k, t_near);
          lx = Select(enter, k == 0 ? sign : zero, lx);
          ly = Select(enter, k == 1 ? sign : zero, ly);
          lz = Select(enter, k == 2 ? sign : zero, lz);
          has_axis = has_axis | enter;
          t_far = Select(parallel, t_far, F4(_mm_min_ps(far_k.m, t_far.m)));  // std::min
          miss = miss | Select(parallel, outside, t_near > t_far);
        }
        const M4 hit = AndNot(lanes & has_axis, miss) & NotLessEqual(t_near, 1e-6f) &
                       NotGreaterEqual(t_near, Load4(&out->t[i]));
        if (!Bits(hit)) return;
        // On a side face the normal is turned back by the yaw; on top or bottom it is +-z.
        const M4 side = lz == zero;
        on_hit(
            i, hit, d, t_near,
            V3{Select(side, cy * lx - sy * ly, zero), Select(side, sy * lx + cy * ly, zero), lz});
      });
      return;
    }
    if (p.kind == PrimitiveKind::kCylinder || p.kind == PrimitiveKind::kRing) {
      // Cylinders and rings in double precision, two rays at a time.
      for_each_group([&](size_t i, M4 lanes, const V3& d) SLAMO_ALWAYS_INLINE {
        const __m128 t_old = _mm_loadu_ps(&out->t[i]);
        const auto half = [&](int shift) SLAMO_ALWAYS_INLINE {
          const auto wide = [&](__m128 x) SLAMO_ALWAYS_INLINE {
            return D2(_mm_cvtps_pd(shift ? _mm_movehl_ps(x, x) : x));
          };
          return IntersectCylinder2(p, origin, wide(d.x.m), wide(d.y.m), wide(d.z.m), wide(t_old));
        };
        const Hit2 lo = half(0), hi = half(1);
        const M4 hit = lanes & ToM4(lo.hit, hi.hit);
        if (!Bits(hit)) return;
        on_hit(i, hit, d, ToF4(lo.t, hi.t),
               V3{ToF4(lo.nx, hi.nx), ToF4(lo.ny, hi.ny), ToF4(lo.nz, hi.nz)});
      });
      return;
    }
    // Everything else in double precision, one pixel at a time, shaded four at a time.
    for_each_group([&](size_t i, M4 lanes, const V3& d) SLAMO_ALWAYS_INLINE {
      alignas(16) float dx[4], dy[4], dz[4], t_lane[4], nx[4], ny[4], nz[4];
      _mm_store_ps(dx, d.x.m), _mm_store_ps(dy, d.y.m), _mm_store_ps(dz, d.z.m);
      const int valid = Bits(lanes);
      alignas(16) int32_t hit_lane[4] = {0, 0, 0, 0};
      for (int k = 0; k < 4; ++k) {
        t_lane[k] = 0.0f, nx[k] = ny[k] = nz[k] = 0.0f;
        if (!(valid >> k & 1)) continue;
        const Vector3d dd = Vector3f(dx[k], dy[k], dz[k]).cast<double>();
        double t = 0.0;
        Vector3d n = Vector3d::Zero();
        if (Intersect(p, origin, dd, &t, &n) && t < out->t[i + k]) {
          hit_lane[k] = -1;
          t_lane[k] = static_cast<float>(t);
          nx[k] = static_cast<float>(n.x()), ny[k] = static_cast<float>(n.y());
          nz[k] = static_cast<float>(n.z());
        }
      }
      const M4 hit{_mm_castsi128_ps(_mm_load_si128(reinterpret_cast<const __m128i*>(hit_lane)))};
      if (!Bits(hit)) return;
      on_hit(i, hit, d, F4(_mm_load_ps(t_lane)),
             V3{F4(_mm_load_ps(nx)), F4(_mm_load_ps(ny)), F4(_mm_load_ps(nz))});
    });
  };
  // Writes the hit lanes of four pixels: depth, id, colour and the no-depth flag; `behind`,
  // when given, is what the colour buffer holds there.
  const auto store = [&](size_t i, M4 hit, F4 t, int id, const V3& c, M4 no_depth,
                         const V3* behind = nullptr) SLAMO_ALWAYS_INLINE {
    const __m128i ids = _mm_set1_epi16(static_cast<int16_t>(static_cast<uint16_t>(id)));
    __m128i* id_at = reinterpret_cast<__m128i*>(&out->id[i]);
    // The flags as four bytes 0 or 1.
    const __m128i flags16 = _mm_packs_epi32(_mm_castps_si128(no_depth.m), _mm_setzero_si128());
    const __m128i flags8 =
        _mm_and_si128(_mm_packs_epi16(flags16, _mm_setzero_si128()), _mm_set1_epi8(1));
    if (Bits(hit) == 0xf) {  // all four: nothing to keep
      _mm_storeu_ps(&out->t[i], t.m);
      _mm_storel_epi64(id_at, ids);
      StoreRgb4(&out->colour[i], c.x, c.y, c.z);
      const int flags = _mm_cvtsi128_si32(flags8);
      std::memcpy(&out->no_depth[i], &flags, 4);
      return;
    }
    _mm_storeu_ps(&out->t[i], Select(hit, t, Load4(&out->t[i])).m);
    const __m128i hit16 = _mm_packs_epi32(_mm_castps_si128(hit.m), _mm_setzero_si128());
    _mm_storel_epi64(id_at, _mm_or_si128(_mm_and_si128(hit16, ids),
                                         _mm_andnot_si128(hit16, _mm_loadl_epi64(id_at))));
    V3 old;
    if (behind) {
      old = *behind;
    } else {
      LoadRgb4(&out->colour[i], &old.x, &old.y, &old.z);
    }
    StoreRgb4(&out->colour[i], Select(hit, c.x, old.x), Select(hit, c.y, old.y),
              Select(hit, c.z, old.z));
    const __m128i hit8 = _mm_packs_epi16(hit16, _mm_setzero_si128());
    int old_flags;
    std::memcpy(&old_flags, &out->no_depth[i], 4);
    const int flags = _mm_cvtsi128_si32(_mm_or_si128(
        _mm_and_si128(hit8, flags8), _mm_andnot_si128(hit8, _mm_cvtsi32_si128(old_flags))));
    std::memcpy(&out->no_depth[i], &flags, 4);
  };
  const V3 to_light{to_light_f.x(), to_light_f.y(), to_light_f.z()};
  const F4 ambient4(ambient_f), diffuse4(diffuse_f);
  // shade_f for four normals: albedo * tint * (ambient + diffuse * max(0, n . l)).
  const auto shade4 = [&](const Vector3f& albedo_tint, const V3& n) SLAMO_ALWAYS_INLINE {
    const F4 lambert = ambient4 + diffuse4 * MaxZero(Dot(n, to_light));
    return V3{F4(albedo_tint.x()) * lambert, F4(albedo_tint.y()) * lambert,
              F4(albedo_tint.z()) * lambert};
  };
  for (const Primitive& p : primitives) {
    const Vector3f albedo_tint = p.albedo.cast<float>().cwiseProduct(tint_f);
    const M4 black{
        _mm_castsi128_ps(_mm_set1_epi32(Luminance(p.albedo) < options_.black_albedo ? -1 : 0))};
    for_each_hit(p, [&](size_t i, M4 hit, const V3& d, F4 t, const V3& n) SLAMO_ALWAYS_INLINE {
      V3 c = shade4(albedo_tint, n);
      if (p.glossy) {
        // Facing away from the half vector (n . h <= 0 before normalising), n . h / |h| is at
        // most a few 1e-7 and its 40th power is 0 in float: no highlight, as computed in full.
        const V3 dn = Normalized(d);
        const V3 h{to_light.x - dn.x, to_light.y - dn.y, to_light.z - dn.z};
        const M4 facing = Dot(n, h) > F4(0.0f);
        if (Bits(facing & hit)) {
          const F4 highlight = F4(0.25f) * PowInt4(MaxZero(Dot(n, Normalized(h))), 40);
          c = V3{Select(facing, c.x + highlight, c.x), Select(facing, c.y + highlight, c.y),
                 Select(facing, c.z + highlight, c.z)};
        }
      }
      store(i, hit, t, p.id, c, black);
    });
  }

  // 3. Semi-transparent objects, far to near, blended over what is behind them.
  std::sort(transparent.begin(), transparent.end(), [&](const Primitive& a, const Primitive& b) {
    return (a.center - origin).squaredNorm() > (b.center - origin).squaredNorm();
  });

  // spec > specular_dropout (a double) in float: above the largest float not above it.
  float dropout = static_cast<float>(options_.specular_dropout);
  if (static_cast<double>(dropout) > options_.specular_dropout) {
    dropout = std::nextafter(dropout, -kInf);
  }
  const F4 dropout4(dropout);
  for (const Primitive& p : transparent) {
    const Vector3f tint = p.albedo.cast<float>();
    const F4 opacity = static_cast<float>(p.opacity);
    const F4 clear = 1.0f - static_cast<float>(p.opacity);
    const Vector3f albedo_tint = p.albedo.cast<float>().cwiseProduct(tint_f);
    const Vector3f filter = Vector3f::Constant(0.35f) + 0.65f * tint;
    for_each_hit(p, [&](size_t i, M4 hit, const V3& d, F4 t, const V3& n) SLAMO_ALWAYS_INLINE {
      const V3 dn = Normalized(d);
      const V3 view{-dn.x, -dn.y, -dn.z};
      // Thin tinted plastic: the background shows through, filtered by the tint.
      V3 behind;
      LoadRgb4(&out->colour[i], &behind.x, &behind.y, &behind.z);
      const V3 shaded = shade4(albedo_tint, n);
      V3 c{opacity * shaded.x + clear * (behind.x * F4(filter.x())),
           opacity * shaded.y + clear * (behind.y * F4(filter.y())),
           opacity * shaded.z + clear * (behind.z * F4(filter.z()))};
      // Reflections: the ceiling lights as bright low-saturation patches, stronger at
      // grazing angles (Fresnel), plus the light's specular highlight.
      const F4 n_dot_view = Dot(n, view);
      const F4 twice = F4(2.0f) * n_dot_view;
      const V3 reflected{twice * n.x - view.x, twice * n.y - view.y, twice * n.z - view.z};
      const F4 grazing = F4(1.0f) - MaxZero(n_dot_view);
      const F4 fresnel = F4(0.1f) + F4(0.9f) * (grazing * grazing) * (grazing * grazing);
      // Six ceiling light bands around the azimuth: sin(6 phi) from (x + iy)^6, no trig (the
      // products std::complex<float> takes: re = ac - bd, im = ad + bc).
      const F4 q = (reflected.z - 0.45f) / 0.25f;
      F4 ceiling = Select(q < F4(0.0f), 0.0f, Select(F4(1.0f) < q, 1.0f, q));  // std::clamp
      const M4 lit = ceiling > F4(0.0f);
      if (Bits(lit & hit)) {
        const F4 rx = reflected.x, ry = reflected.y;
        const F4 r2 = rx * rx + ry * ry;
        const F4 c2_re = rx * rx - ry * ry, c2_im = rx * ry + ry * rx;
        const F4 c4_re = c2_re * c2_re - c2_im * c2_im, c4_im = c2_re * c2_im + c2_im * c2_re;
        const F4 c6_im = c4_re * c2_im + c4_im * c2_re;
        ceiling = Select(lit, ceiling * (F4(0.5f) + F4(0.5f) * c6_im / (r2 * r2 * r2)), ceiling);
      }
      const F4 patch = MinOne(fresnel * 0.6f + F4(0.7f) * ceiling);
      // As for glossy solids: n . h <= 0 before normalising means a highlight of exactly 0.
      const V3 h{view.x + to_light.x, view.y + to_light.y, view.z + to_light.z};
      const M4 facing = Dot(n, h) > F4(0.0f);
      F4 spec = 0.0f;
      if (Bits(facing & hit)) {
        spec = Select(facing, F4(0.9f) * PowInt4(MaxZero(Dot(n, Normalized(h))), 60), 0.0f);
      }
      const F4 keep = F4(1.0f) - patch, glare = patch * F4(0.85f);
      c = V3{keep * c.x + glare + spec, keep * c.y + glare + spec, keep * c.z + glare + spec};
      store(i, hit, t, p.id, c, spec > dropout4, &behind);
    });
  }
}

SLAMO_AVX_CLONES RgbdFrame SimRenderer::Render(const SimWorld& world, const Pose2D& robot,
                                               double t_s, FrameTruth* truth) {
  const int w = camera_.width_px;
  const int h = camera_.height_px;
  const Eigen::Isometry3d world_from_camera = CameraPose(robot);
  Buffers& depth_pass = *depth_buffers_;
  if (options_.arena) {
    // A new hall for every frame, from the seed and the frame's index.
    arena_ = MakeArenaBackdrop(season_, options_.arena_options,
                               seed_ * 0x9E3779B97F4A7C15ULL + static_cast<uint64_t>(frame_index_));
  }
  const ArenaBackdrop* arena = options_.arena ? &arena_ : nullptr;
  RenderPass(world, world_from_camera, arena, &depth_pass);
  Buffers& colour_pass_storage = *colour_buffers_;
  const Buffers* colour_pass = &depth_pass;
  if (options_.colour_depth_baseline && camera_.colour_depth_baseline_m != 0.0) {
    Eigen::Isometry3d colour_pose = world_from_camera;
    colour_pose.translation() +=
        world_from_camera.linear() * Vector3d(camera_.colour_depth_baseline_m, 0, 0);
    RenderPass(world, colour_pose, arena, &colour_pass_storage);
    colour_pass = &colour_pass_storage;
  }

  RgbdFrame frame;
  frame.t_s = t_s;
  frame.index = frame_index_++;
  frame.colour.create(h, w, CV_8UC3);
  frame.depth_mm.create(h, w, CV_16UC1);
  // Noise comes from the pool, from a random offset each frame (contiguous: SIMD-friendly).
  // The pool is drawn at the first frame (the first draws of rng_, as when the constructor
  // drew it): a match that never looks (the scripted route) never pays for its million draws.
  if (normal_pool_.empty()) FillNormalPool();
  const size_t n = static_cast<size_t>(w) * h;
  std::uniform_int_distribution<size_t> offset(0, normal_pool_.size() - 3 * n);
  const float* colour_noise = normal_pool_.data() + offset(rng_);
  const float* depth_noise = normal_pool_.data() + offset(rng_);

  // Colour: 255 * linear RGB + sigma * N(0, 1), to 8-bit BGR, with OpenCV's vector code, a
  // band of pixels at a time so the intermediate images stay in cache. Each band starts a
  // multiple of 64 floats into the image, so every element goes through the same code
  // (vector body or tail) as when the whole image was converted at once.
  constexpr size_t kBand = 4096;  // pixels
  const float* colour_all = colour_pass->colour.data()->data();
  uint8_t* bgr = frame.colour.ptr<uint8_t>(0);
  cv::Mat scaled, rgb8;
  for (size_t p0 = 0; p0 < n; p0 += kBand) {
    const int count = static_cast<int>(std::min(kBand, n - p0));
    const cv::Mat colour_f(1, count, CV_32FC3, const_cast<float*>(colour_all + 3 * p0));
    if (options_.colour_noise) {
      const cv::Mat noise(1, count, CV_32FC3, const_cast<float*>(colour_noise + 3 * p0));
      cv::scaleAdd(noise, options_.colour_noise_sigma / 255.0, colour_f, scaled);
    } else {
      scaled = colour_f;
    }
    scaled.convertTo(rgb8, CV_8UC3, 255.0);
    cv::Mat bgr_band(1, count, CV_8UC3, bgr + 3 * p0);
    cv::cvtColor(rgb8, bgr_band, cv::COLOR_RGB2BGR);
  }

  // Depth: the camera's linear error, then sigma(d) noise, in whole millimetres.
  const float a = static_cast<float>(options_.depth_bias ? camera_.depth_correction.a : 1.0);
  const float b_mm = static_cast<float>(options_.depth_bias ? camera_.depth_correction.b_mm : 0.0);
  const float min_range = static_cast<float>(camera_.min_range_m);
  const float max_range = static_cast<float>(camera_.max_range_m);
  const size_t sigma_last = sigma_mm_by_mm_.size() - 1;
  uint16_t* depth_out = frame.depth_mm.ptr<uint16_t>(0);
  const auto depth_at = [&](size_t i) -> uint16_t {
    const float z = depth_pass.t[i];
    if (depth_pass.no_depth[i] || !(z >= min_range && z <= max_range)) return 0;  // inf too
    float measured_mm = a * z * 1000.0f + b_mm;
    if (options_.depth_noise) {
      measured_mm +=
          sigma_mm_by_mm_[std::min(sigma_last, static_cast<size_t>(z * 1000.0f))] * depth_noise[i];
    }
    return static_cast<uint16_t>(std::clamp(measured_mm + 0.5f, 0.0f, 65535.0f));
  };
  // Four pixels at a time, the same float operations as depth_at; sigma(d) looked up per lane.
  const F4 a4(a), b4(b_mm), mm(1000.0f), near4(min_range), far4(max_range), top(65535.0f);
  const __m128i last = _mm_set1_epi32(static_cast<int>(sigma_last));
  size_t i = 0;
  for (; i + 4 <= n; i += 4) {
    const F4 z = Load4(&depth_pass.t[i]);
    int flags;
    std::memcpy(&flags, &depth_pass.no_depth[i], 4);
    const __m128i flags32 = _mm_unpacklo_epi16(
        _mm_unpacklo_epi8(_mm_cvtsi32_si128(flags), _mm_setzero_si128()), _mm_setzero_si128());
    const M4 reads = M4{_mm_castsi128_ps(_mm_cmpeq_epi32(flags32, _mm_setzero_si128()))} &
                     (z >= near4) & (z <= far4);
    if (!Bits(reads)) {
      _mm_storel_epi64(reinterpret_cast<__m128i*>(depth_out + i), _mm_setzero_si128());
      continue;
    }
    F4 measured_mm = a4 * z * mm + b4;
    if (options_.depth_noise) {
      // The table index as static_cast<size_t>, within the table (0 where nothing is read).
      __m128i index = _mm_and_si128(_mm_cvttps_epi32((z * mm).m), _mm_castps_si128(reads.m));
      const __m128i over = _mm_cmpgt_epi32(index, last);
      index = _mm_or_si128(_mm_and_si128(over, last), _mm_andnot_si128(over, index));
      alignas(16) int32_t k[4];
      _mm_store_si128(reinterpret_cast<__m128i*>(k), index);
      const F4 sigma(_mm_setr_ps(sigma_mm_by_mm_[k[0]], sigma_mm_by_mm_[k[1]],
                                 sigma_mm_by_mm_[k[2]], sigma_mm_by_mm_[k[3]]));
      measured_mm = measured_mm + sigma * Load4(depth_noise + i);
    }
    const F4 x = measured_mm + 0.5f;
    const F4 clamped = Select(x < F4(0.0f), 0.0f, Select(top < x, top, x));  // std::clamp
    // To uint16 by truncation; biased by 2^15 for SSE2's signed 16-bit pack.
    const __m128i depth = _mm_and_si128(_mm_cvttps_epi32(clamped.m), _mm_castps_si128(reads.m));
    const __m128i packed = _mm_xor_si128(
        _mm_packs_epi32(_mm_sub_epi32(depth, _mm_set1_epi32(32768)), _mm_setzero_si128()),
        _mm_set1_epi16(static_cast<int16_t>(0x8000)));
    _mm_storel_epi64(reinterpret_cast<__m128i*>(depth_out + i), packed);
  }
  for (; i < n; ++i) depth_out[i] = depth_at(i);

  if (truth) {
    truth->robot = robot;
    truth->world_from_camera = world_from_camera;
    truth->objects.clear();
    truth->landmarks.clear();
    truth->ids = cv::Mat(h, w, CV_16UC1, const_cast<uint16_t*>(depth_pass.id.data())).clone();
    // Pixel counts and boxes per id: the extreme columns and rows of each id's pixels (the
    // same boxes as the union of one-pixel rectangles, without a rectangle union per pixel).
    struct Extent {
      int count = 0;
      int u0 = 0, v0 = 0, u1 = 0, v1 = 0;
    };
    std::vector<Extent> extents(kLandmarkIdBase + season_.landmarks.size());
    // A row at a time in runs of one id (found eight ids at a time): a run adds its length
    // and widens the box to its ends, as its pixels one by one would.
    for (int v = 0; v < h; ++v) {
      const uint16_t* row = depth_pass.id.data() + static_cast<size_t>(v) * w;
      for (int u = 0; u < w;) {
        const uint16_t id = row[u];
        const __m128i same = _mm_set1_epi16(static_cast<int16_t>(id));
        int end = u + 1;
        for (; end + 8 <= w; end += 8) {
          const __m128i ids = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + end));
          const int equal = _mm_movemask_epi8(_mm_cmpeq_epi16(ids, same));
          if (equal != 0xffff) {
            end += __builtin_ctz(~equal) / 2;
            break;
          }
        }
        if (end + 8 > w) {
          while (end < w && row[end] == id) ++end;
        }
        if (id != 0 && id < extents.size()) {
          Extent& e = extents[id];
          if (e.count == 0) {
            e.u0 = u, e.u1 = end - 1, e.v0 = e.v1 = v;
          } else {
            e.u0 = std::min(e.u0, u), e.u1 = std::max(e.u1, end - 1), e.v1 = v;  // rows in order
          }
          e.count += end - u;
        }
        u = end;
      }
    }
    const auto box_of = [&](int id) {
      const Extent& e = extents[id];
      return cv::Rect(e.u0, e.v0, e.u1 - e.u0 + 1, e.v1 - e.v0 + 1);
    };
    const Eigen::Isometry3d camera_from_world = world_from_camera.inverse();
    for (const SimObject& object : world.objects) {
      if (object.id >= static_cast<int>(extents.size()) || extents[object.id].count == 0) continue;
      truth->objects.push_back({object.id, object.type->name, object.colour, object.center_m,
                                camera_from_world * object.center_m, extents[object.id].count,
                                box_of(object.id)});
    }
    for (size_t l = 0; l < season_.landmarks.size(); ++l) {
      const int id = kLandmarkIdBase + static_cast<int>(l);
      if (extents[id].count == 0) continue;
      const Vector3d& position = landmark_centres_[l];
      truth->landmarks.push_back({static_cast<int>(l), position, camera_from_world * position,
                                  extents[id].count, box_of(id)});
    }
  }
  return frame;
}

}  // namespace slamo::platform
