/* The exact level's double-precision re-tests (RTCL_PRECISION_EXACT): one
 * primitive against one ray, for every candidate the float test cannot
 * decide. Shared by the single-ray and packet callers. OpenCL C only. */
#ifndef RTCL_SHARED_EXACT_H
#define RTCL_SHARED_EXACT_H

#include "shared/ray.h"

#ifdef RTCL_PRECISION_EXACT

/* Relative bound, in units of FLT_EPSILON * R^2, on the float rounding error
 * of a shear-space edge function whose inputs have magnitude at most R
 * (each input: two or three rounded operations, the products and the
 * difference: a few ulps of R^2; 64 leaves a wide margin). */
#define RTCL_EXACT_EDGE_ULPS 64.0f
/* Relative slack on a candidate's float t against tmin and the best t. */
#define RTCL_EXACT_T_SLACK 1e-3f

/* Lanes that float cannot rule out: inside the triangle by the loose
 * bound, and t near [tmin, t_best] or grazing (det near zero). Every
 * argument is per lane (a single-ray caller broadcasts its ray). A..C are
 * the shear-space vertex coordinates of the watertight test. */
inline int8 rtcl_exact_triangle_candidates(float8 Ax, float8 Ay, float8 Az, float8 Bx, float8 By, float8 Bz,
                                           float8 Cx, float8 Cy, float8 Cz, float8 U, float8 V, float8 W,
                                           float8 sz, float8 tmin, float8 t_best) {
  float8 R = fmax(fmax(fmax(fabs(Ax), fabs(Ay)), fmax(fabs(Bx), fabs(By))), fmax(fabs(Cx), fabs(Cy)));
  R = fmax(R, fmax(fmax(fabs(Az), fabs(Bz)), fabs(Cz)));
  float8 E = (RTCL_EXACT_EDGE_ULPS * FLT_EPSILON) * R * R;
  int8 inside = ((U >= -E) & (V >= -E) & (W >= -E)) | ((U <= E) & (V <= E) & (W <= E));
  float8 det = U + V + W;
  float8 t = sz * (U * Az + V * Bz + W * Cz) / det;
  float8 slack = (fabs(t) + R * fabs(sz)) * RTCL_EXACT_T_SLACK;
  int8 near_range = (t >= tmin - slack) & (t <= t_best + slack);
  return inside & ((fabs(det) <= 4.0f * E) | near_range);
}

/* The watertight test (Woop, Benthin, Wald 2013) in double for one triangle,
 * its vertices a, b, c given on the ray's permuted axes (kx, ky, kz) and the
 * ray as its permuted origin and direction. Returns t (+inf when the ray
 * misses or lies in the triangle's plane) and the barycentrics u, v. Inputs
 * are floats, so every difference of two of them is exact in double. */
inline double exact_triangle(float ax, float ay, float az, float bx, float by, float bz, float cx, float cy,
                             float cz, float okx, float oky, float okz, float dkx, float dky, float dkz, double* u,
                             double* v) {
  double sx = (double)dkx / (double)dkz, sy = (double)dky / (double)dkz, sz = 1.0 / (double)dkz;
  double Az = (double)az - (double)okz, Bz = (double)bz - (double)okz, Cz = (double)cz - (double)okz;
  double Ax = (double)ax - (double)okx - sx * Az, Ay = (double)ay - (double)oky - sy * Az;
  double Bx = (double)bx - (double)okx - sx * Bz, By = (double)by - (double)oky - sy * Bz;
  double Cx = (double)cx - (double)okx - sx * Cz, Cy = (double)cy - (double)oky - sy * Cz;
  double U = Cx * By - Cy * Bx;
  double V = Ax * Cy - Ay * Cx;
  double W = Bx * Ay - By * Ax;
  if ((U < 0.0 || V < 0.0 || W < 0.0) && (U > 0.0 || V > 0.0 || W > 0.0)) return INFINITY;
  double det = U + V + W;
  if (det == 0.0) return INFINITY;
  *u = V / det;
  *v = W / det;
  return sz * (U * Az + V * Bz + W * Cz) / det;
}

/* A sphere in double (Haines et al., Ray Tracing Gems ch. 7): the nearest
 * root in [tmin, tmax], +inf when none. */
inline double exact_sphere(float cx, float cy, float cz, float r, float ox, float oy, float oz, float dx, float dy,
                           float dz, float tmin, float tmax) {
  double fx = (double)ox - (double)cx, fy = (double)oy - (double)cy, fz = (double)oz - (double)cz;
  double a = (double)dx * dx + (double)dy * dy + (double)dz * dz;
  double b = -(fx * dx + fy * dy + fz * dz);
  double k = b / a;
  double lx = fx + k * dx, ly = fy + k * dy, lz = fz + k * dz;
  double rr = (double)r * (double)r;
  double disc = a * (rr - (lx * lx + ly * ly + lz * lz));
  if (!(disc >= 0.0)) return INFINITY;
  double c = fx * fx + fy * fy + fz * fz - rr;
  double q = b + copysign(sqrt(disc), b);
  double t0 = c / q, t1 = q / a;
  double tn = fmin(t0, t1), tf = fmax(t0, t1);
  if (tn >= tmin && tn <= tmax) return tn;
  if (tf >= tmin && tf <= tmax) return tf;
  return INFINITY;
}

/* Whether a double-precision hit at t on prim beats the best so far: finite
 * (a miss is +inf), inside [tmin, tmax], and nearer, or as near with the smaller primitive id. */
inline int exact_better(double t, int prim, double t_best, int prim_best, float tmin, float tmax) {
  return t >= (double)tmin && t <= (double)tmax && t < (double)INFINITY && (t < t_best || (t == t_best && (prim_best < 0 || prim < prim_best)));
}

#endif
#endif
