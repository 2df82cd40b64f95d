/* Sample patterns of the distributed ray tracer, shared by the device kernels
 * and the host reference renderer (tests/support/reference_renderer.cpp) so
 * both draw the same points. Every value is a pure function of (seed, pixel,
 * dimension, sample index): pixels rendered in any order, in any tile or
 * batch, get the same samples.
 *
 * A "dimension" is one 2D decision of a path: the sub-pixel position, the
 * lens position, one light's point at one bounce, one glossy direction at one
 * bounce (rtcl_dimension_*). Within a dimension a pixel draws `count` points
 * (spp, or spp * light samples), index 0 .. count - 1.
 *
 * Samplers (RTCL_SAMPLER_*):
 *  - random: independent uniform points (hash of seed, pixel, dimension,
 *    index);
 *  - stratified: jittered on a k x k grid of strata when count = k^2, else
 *    Latin hypercube (n-rooks: one point in each of `count` columns and
 *    rows); the strata a sample index lands in are shuffled per pixel and
 *    dimension, except the sub-pixel dimension; one sample in the sub-pixel
 *    dimension is the pixel centre;
 *  - sobol: the first two dimensions of the Sobol sequence, Owen-scrambled
 *    (Owen 1995, hash-based) per pixel and dimension, the
 *    index shuffled per pixel and dimension within the next power of two
 *    (Burley, "Practical Hash-based Owen Scrambling", JCGT 2020): for count
 *    = 2^m the points of a pixel's dimension form a (0, m, 2)-net.
 *
 * Floats are built from the top 24 bits of 32-bit values, so host and device
 * compute identical uniforms; only the warps with transcendental functions
 * (filter, lens, lobe) may differ by an ulp between them. Include after
 * shared/layouts.h (rtcl_u32) and shared/render_layouts.h (rtcl_hash). */
#ifndef RTCL_SHARED_SAMPLING_H
#define RTCL_SHARED_SAMPLING_H

#ifdef __OPENCL_VERSION__
#define RTCL_SQRTF(x) sqrt(x)
#define RTCL_LOGF(x) log(x)
#define RTCL_EXPF(x) exp(x)
#define RTCL_COSF(x) cos(x)
#define RTCL_SINF(x) sin(x)
#define RTCL_POWF(x, y) pow(x, y)
#else
#include <math.h>
#define RTCL_SQRTF(x) sqrtf(x)
#define RTCL_LOGF(x) logf(x)
#define RTCL_EXPF(x) expf(x)
#define RTCL_COSF(x) cosf(x)
#define RTCL_SINF(x) sinf(x)
#define RTCL_POWF(x, y) powf(x, y)
namespace rtcl {
#endif

#define RTCL_SAMPLER_STRATIFIED 0u
#define RTCL_SAMPLER_RANDOM 1u
#define RTCL_SAMPLER_SOBOL 2u

/* Reconstruction filters (RTCL_FILTER_*), applied by filter importance
 * sampling: each sample's offset from the pixel centre is drawn from the
 * filter, and every sample of a pixel weighs the same.
 *  - box: offsets uniform over the pixel (the sampler's points as they are);
 *  - gaussian: offsets from the radially symmetric Gaussian of standard
 *    deviation RTCL_GAUSSIAN_SIGMA pixels truncated at radius
 *    RTCL_GAUSSIAN_RADIUS pixels, by inverting its radial CDF. */
#define RTCL_FILTER_BOX 0u
#define RTCL_FILTER_GAUSSIAN 1u
#define RTCL_GAUSSIAN_SIGMA 0.5f
#define RTCL_GAUSSIAN_RADIUS 1.5f

#define RTCL_PI_F 3.14159265358979323846f

/* Dimensions: 0 sub-pixel, 1 lens, then per bounce depth d (0 = the camera
 * ray's hit) one per light and one for the glossy lobe. */
#define RTCL_DIM_PIXEL 0u
#define RTCL_DIM_LENS 1u
inline rtcl_u32 rtcl_dimension_light(rtcl_u32 depth, rtcl_u32 light_count, rtcl_u32 light) {
  return 2u + depth * (light_count + 1u) + light;
}
inline rtcl_u32 rtcl_dimension_glossy(rtcl_u32 depth, rtcl_u32 light_count) {
  return 2u + depth * (light_count + 1u) + light_count;
}

inline float rtcl_unit_float(rtcl_u32 bits) { return (float)(bits >> 8) * (1.0f / 16777216.0f); }

/* A key for one (seed, pixel, dimension, purpose). */
inline rtcl_u32 rtcl_sample_key(rtcl_u32 seed, rtcl_u32 pixel, rtcl_u32 dimension, rtcl_u32 purpose) {
  return rtcl_hash(rtcl_hash(rtcl_hash(seed ^ 0x2545f491u) ^ pixel) ^ (dimension * 0x9e3779b9u + purpose));
}

/* A bijection of [0, 2^bits) chosen by `key` (odd multiplications, xor-shifts
 * and additions modulo 2^bits are each invertible). */
inline rtcl_u32 rtcl_mix_bits(rtcl_u32 x, rtcl_u32 bits, rtcl_u32 key) {
  rtcl_u32 mask = bits >= 32u ? 0xffffffffu : (1u << bits) - 1u;
  rtcl_u32 shift = bits / 2u + 1u;
  for (rtcl_u32 round = 0; round < 3u; ++round) {
    rtcl_u32 k = rtcl_hash(key + round);
    x = (x * (k | 1u)) & mask;
    x = (x + (k >> 7)) & mask;
    x ^= x >> shift;
  }
  return x;
}

/* A permutation of [0, n) chosen by `key` (cycle walking over the bijection
 * of the next power of two: each step stays in the same cycle, so it ends). */
inline rtcl_u32 rtcl_permute(rtcl_u32 i, rtcl_u32 n, rtcl_u32 key) {
  if (n <= 1u) return 0u;
  rtcl_u32 bits = 1u;
  while (bits < 32u && (1u << bits) < n) ++bits;
  do {
    i = rtcl_mix_bits(i, bits, key);
  } while (i >= n);
  return i;
}

/* Sobol dimensions 1 and 2 of point i (dimension 1: the van der Corput
 * sequence, bit-reversed i; dimension 2: direction numbers of Pascal's matrix
 * mod 2, v_{k+1} = v_k xor v_k >> 1) as 32-bit fractions. */
inline rtcl_u32 rtcl_reverse_bits(rtcl_u32 x) {
  x = (x << 16) | (x >> 16);
  x = ((x & 0x00ff00ffu) << 8) | ((x & 0xff00ff00u) >> 8);
  x = ((x & 0x0f0f0f0fu) << 4) | ((x & 0xf0f0f0f0u) >> 4);
  x = ((x & 0x33333333u) << 2) | ((x & 0xccccccccu) >> 2);
  x = ((x & 0x55555555u) << 1) | ((x & 0xaaaaaaaau) >> 1);
  return x;
}
/* Owen scrambling of a 32-bit binary fraction, hash-based (Burley,
 * "Practical Hash-based Owen Scrambling", JCGT 2020, after Laine and Karras
 * 2011): with the bits reversed, adding the key and xoring x with x times an
 * even constant change each bit only by a function of the bits below it, so
 * in the fraction's order each bit flips by a function of the bits above it
 * (the digits naming its interval): the structure of nested uniform
 * scrambling, which keeps the stratification of any (t, m, s)-net. Four
 * multiplications instead of a hash per bit. */
inline rtcl_u32 rtcl_owen_scramble(rtcl_u32 x, rtcl_u32 key) {
  x = rtcl_reverse_bits(x);
  x += key;
  x ^= x * 0x6c50b47cu;
  x ^= x * 0xb82f1e52u;
  x ^= x * 0xc7afe638u;
  x ^= x * 0x8d22f6e6u;
  return rtcl_reverse_bits(x);
}
/* Sobol dimension 2 of point i (above). */
inline rtcl_u32 rtcl_sobol_second(rtcl_u32 i) {
  rtcl_u32 r = 0u;
  for (rtcl_u32 v = 0x80000000u; i != 0u; i >>= 1, v ^= v >> 1)
    if (i & 1u) r ^= v;
  return r;
}

/* The smallest k with k * k >= n (n < 2^31), exact whatever the rounding of
 * the device's sqrt. */
inline rtcl_u32 rtcl_ceil_sqrt(rtcl_u32 n) {
  rtcl_u32 k = (rtcl_u32)RTCL_SQRTF((float)n);
  while (k > 0u && k * k > n) --k;
  while ((k + 1u) * (k + 1u) <= n) ++k;
  return k * k < n ? k + 1u : k;
}

/* Point `index` (< count) of `pixel` in `dimension`, in [0, 1)^2. */
inline void rtcl_sample_2d(rtcl_u32 sampler, rtcl_u32 seed, rtcl_u32 pixel, rtcl_u32 dimension, rtcl_u32 index,
                           rtcl_u32 count, float* u, float* v) {
  if (sampler == RTCL_SAMPLER_RANDOM) {
    rtcl_u32 h = rtcl_hash(rtcl_sample_key(seed, pixel, dimension, 0u) ^ rtcl_hash(index));
    *u = rtcl_unit_float(h);
    *v = rtcl_unit_float(rtcl_hash(h ^ 0x68bc21ebu));
    return;
  }
  if (sampler == RTCL_SAMPLER_SOBOL) {
    rtcl_u32 bits = 0u;
    while (bits < 32u && (1u << bits) < count) ++bits;
    rtcl_u32 i = bits == 0u ? 0u : rtcl_mix_bits(index, bits, rtcl_sample_key(seed, pixel, dimension, 1u));
    *u = rtcl_unit_float(rtcl_owen_scramble(rtcl_reverse_bits(i), rtcl_sample_key(seed, pixel, dimension, 2u)));
    *v = rtcl_unit_float(rtcl_owen_scramble(rtcl_sobol_second(i), rtcl_sample_key(seed, pixel, dimension, 3u)));
    return;
  }
  /* stratified */
  if (count <= 1u && dimension == RTCL_DIM_PIXEL) {
    *u = 0.5f;
    *v = 0.5f;
    return;
  }
  rtcl_u32 key = rtcl_sample_key(seed, pixel, dimension, 4u);
  rtcl_u32 stratum = dimension == RTCL_DIM_PIXEL ? index : rtcl_permute(index, count, key);
  rtcl_u32 h1 = rtcl_hash(key ^ rtcl_hash(index + 0x632be5abu));
  float ju = rtcl_unit_float(h1), jv = rtcl_unit_float(rtcl_hash(h1 ^ 0x68bc21ebu));
  rtcl_u32 k = rtcl_ceil_sqrt(count);
  if (k * k == count) {
    float inv_k = 1.0f / (float)k;
    *u = ((float)(stratum % k) + ju) * inv_k;
    *v = ((float)(stratum / k) + jv) * inv_k;
  } else {
    float inv_n = 1.0f / (float)count;
    *u = ((float)stratum + ju) * inv_n;
    *v = ((float)rtcl_permute(stratum, count, key ^ 0x7f4a7c15u) + jv) * inv_n;
  }
}

/* Offset from the pixel centre (pixels) of a sample at (u, v) in [0, 1)^2
 * under `filter`. */
inline void rtcl_filter_offset(rtcl_u32 filter, float u, float v, float* dx, float* dy) {
  if (filter == RTCL_FILTER_GAUSSIAN) {
    const float s2 = 2.0f * RTCL_GAUSSIAN_SIGMA * RTCL_GAUSSIAN_SIGMA;
    float tail = 1.0f - RTCL_EXPF(-RTCL_GAUSSIAN_RADIUS * RTCL_GAUSSIAN_RADIUS / s2);
    float r = RTCL_SQRTF(-s2 * RTCL_LOGF(1.0f - u * tail));
    float phi = 2.0f * RTCL_PI_F * v;
    *dx = r * RTCL_COSF(phi);
    *dy = r * RTCL_SINF(phi);
    return;
  }
  *dx = u - 0.5f;
  *dy = v - 0.5f;
}

/* (u, v) in [0, 1)^2 to the unit disc, area-preserving and keeping strata
 * compact (Shirley and Chiu's concentric map, 1997). */
inline void rtcl_concentric_disc(float u, float v, float* x, float* y) {
  float a = 2.0f * u - 1.0f, b = 2.0f * v - 1.0f;
  if (a == 0.0f && b == 0.0f) {
    *x = 0.0f;
    *y = 0.0f;
    return;
  }
  float r, phi;
  if (a * a > b * b) {
    r = a;
    phi = (RTCL_PI_F / 4.0f) * (b / a);
  } else {
    r = b;
    phi = (RTCL_PI_F / 2.0f) - (RTCL_PI_F / 4.0f) * (a / b);
  }
  *x = r * RTCL_COSF(phi);
  *y = r * RTCL_SINF(phi);
}

/* A direction of the normalised Phong lobe cos^exponent around the z axis
 * (density (exponent + 1) / (2 pi) cos^exponent per solid angle): its cosine
 * to the axis and the sine, and the azimuth. */
inline void rtcl_phong_lobe(float exponent, float u, float v, float* cos_a, float* sin_a, float* cos_phi,
                            float* sin_phi) {
  float c = RTCL_POWF(1.0f - u, 1.0f / (exponent + 1.0f)); /* 1 - u in (0, 1]: never cos 0 exactly */
  *cos_a = c;
  *sin_a = RTCL_SQRTF(1.0f - c * c > 0.0f ? 1.0f - c * c : 0.0f);
  float phi = 2.0f * RTCL_PI_F * v;
  *cos_phi = RTCL_COSF(phi);
  *sin_phi = RTCL_SINF(phi);
}

/* Phong exponent of a roughness r in (0, 1] (the Beckmann / Blinn-Phong
 * correspondence n = 2 / r^2 - 2, Walter et al. 2007): r = 1 is the cosine
 * lobe's n = 0, small r a sharp lobe. */
inline float rtcl_roughness_exponent(float roughness) { return 2.0f / (roughness * roughness) - 2.0f; }

/* The time dimension (motion blur): one 1D decision per path, shared by all
 * of its rays (a sample is one instant), numbered far above the per-bounce
 * dimensions so that adding it changes no other decision. */
#define RTCL_DIM_TIME 0xfffffff0u

/* Time of sample `index` (< count) of `pixel`, a fraction of the shutter
 * interval in [0, 1): stratified: one jittered point in each of `count`
 * strata, the strata shuffled per pixel; random and sobol: the first
 * coordinate of their 2D point (Sobol's is a scrambled van der Corput
 * sequence, stratified for count = 2^m). */
inline float rtcl_sample_time(rtcl_u32 sampler, rtcl_u32 seed, rtcl_u32 pixel, rtcl_u32 index, rtcl_u32 count) {
  if (sampler == RTCL_SAMPLER_STRATIFIED) {
    rtcl_u32 key = rtcl_sample_key(seed, pixel, RTCL_DIM_TIME, 4u);
    rtcl_u32 stratum = count <= 1u ? 0u : rtcl_permute(index, count, key);
    float jitter = rtcl_unit_float(rtcl_hash(key ^ rtcl_hash(index + 0x632be5abu)));
    float t = ((float)stratum + jitter) * (1.0f / (float)count);
    return t < 1.0f ? t : 0.99999994f; /* rounding up to 1 in the last stratum */
  }
  float u, v;
  rtcl_sample_2d(sampler, seed, pixel, RTCL_DIM_TIME, index, count, &u, &v);
  return u;
}

#ifndef __OPENCL_VERSION__
} /* namespace rtcl */
#endif
#endif
