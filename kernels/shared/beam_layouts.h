/* Records of beam tracing (Heckbert and Hanrahan 1984) that cross the
 * host/device boundary: screen-space polygons, tile beams and the fragments
 * the clipping kernel (kernels/render/beam_clip.cl) writes. Same rules as
 * layouts.h: 4-byte scalar fields only, host static_asserts in
 * src/rtcl/beam/beam_layouts.cpp. Include shared/layouts.h first.
 *
 * Screen space: image pixels, x right, y down, (0, 0) the top-left corner of
 * the image (the camera's perspective already applied, so the viewing beam
 * is a prism along the view depth). */
#ifndef RTCL_SHARED_BEAM_LAYOUTS_H
#define RTCL_SHARED_BEAM_LAYOUTS_H

#ifndef __OPENCL_VERSION__
namespace rtcl {
#endif

/* Vertices of a screen polygon: a triangle clipped by the near plane (one
 * more) and by the four sides of the screen rectangle (one more each). */
#define RTCL_BEAM_POLYGON_VERTS 8
/* Vertices of one convex piece of a beam or fragment. */
#define RTCL_BEAM_PIECE_VERTS 16
/* Convex pieces a beam's remaining cross-section may consist of. */
#define RTCL_BEAM_MAX_PIECES 32

/* A triangle in screen space, convex, counter-clockwise in (x, y): 80 bytes.
 * inv_depth: 1 / s = a x + b y + c over the triangle's plane, s the depth
 * along the camera's view direction (scene units); affine in screen space
 * because the plane is. */
typedef struct BeamPolygon {
  float x[RTCL_BEAM_POLYGON_VERTS], y[RTCL_BEAM_POLYGON_VERTS];
  float inv_depth[3]; /* a, b, c */
  rtcl_u32 count;     /* vertices, 3 .. RTCL_BEAM_POLYGON_VERTS */
} BeamPolygon;

/* One beam: the prism over a convex screen polygon (a tile's square for the
 * viewing beam's tiles, a mirror fragment for a reflected beam) and its
 * candidate polygons candidates[first .. first + count), in walking order
 * (nearest key first): 148 bytes. The kernel works in coordinates relative
 * to (x0, y0), a point near the beam (float precision of its size). */
typedef struct Beam {
  float x[RTCL_BEAM_PIECE_VERTS], y[RTCL_BEAM_PIECE_VERTS]; /* counter-clockwise, pixels */
  float x0, y0;
  rtcl_u32 vertex_count; /* 3 .. RTCL_BEAM_PIECE_VERTS */
  rtcl_u32 first, count;
} Beam;

/* One convex piece of a polygon's visible fragment in one beam: 144 bytes.
 * seq: its position in the beam's output order. */
typedef struct BeamFragment {
  rtcl_u32 beam, polygon, seq, count;
  float x[RTCL_BEAM_PIECE_VERTS], y[RTCL_BEAM_PIECE_VERTS];
} BeamFragment;

/* Status words of one clipping launch (rtcl_u32 each). */
#define RTCL_BEAM_STATUS_FRAGMENTS 0      /* fragments written or wanted (may exceed the capacity) */
#define RTCL_BEAM_STATUS_PIECE_OVERFLOW 1 /* beams whose region needed more than RTCL_BEAM_MAX_PIECES pieces */
#define RTCL_BEAM_STATUS_VERT_OVERFLOW 2  /* beams whose piece needed more than RTCL_BEAM_PIECE_VERTS vertices */
#define RTCL_BEAM_STATUS_FIRST_TILE 3     /* smallest beam index with an overflow; 0xffffffff: none */
#define RTCL_BEAM_STATUS_WORDS 4

#ifndef __OPENCL_VERSION__
}  // namespace rtcl
#endif

#endif
