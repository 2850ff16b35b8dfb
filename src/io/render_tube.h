/* render_tube.h: the camera of the shaded tube images (paper Fig. 6-7): a piece of the tube
 * clipped to z in [-half_len, half_len], seen by an orthographic camera, each pixel shaded by
 * a method's radiance leaving the surface it sees toward the camera.
 *
 * Owns the camera model (image-plane axes, fit of the clipped tube into the image, projection
 * of a 3-D point to pixel coordinates), the ray cast of a pixel onto the tube's faces, and the
 * lookup of the (surface, segment, direction bin) cell a pixel shows. The conventions (frames,
 * bins, segments) are kernels/ppb_conventions.h's: ppb_segment_of and ppb_dir_bin, never
 * re-coded here.
 *
 * Why orthographic: the tube is uniform in z, so a method's radiance depends only on (surface,
 * segment, bin). With an orthographic camera the direction toward the camera is the same for
 * every pixel, so each surface shows one direction bin and the picture varies with position
 * only, as the paper's figures do; a perspective camera would sweep the view direction across
 * bin edges and draw the binning as false contours.
 *
 * Pixel coordinates: (px, py) with px to the right and py downward; pixel (i, j) covers
 * [i, i+1) x [j, j+1) and is shaded from the ray through its centre (i + 0.5, j + 0.5). */
#ifndef PPB_RENDER_TUBE_H
#define PPB_RENDER_TUBE_H

#include <stddef.h>

#include "model/result.h"
#include "model/scene.h"

typedef struct ppb_tube_view {
    double width, height, half_len; /* the clipped box: x in [-W/2, W/2], y in [-H, 0], |z| <= */
    double to_cam[3];               /* unit vector from the tube toward the camera */
    double right[3], up[3];         /* image-plane axes: px grows along right, py against up */
    double u0, v0;                  /* image-plane coordinates of the image's top-left corner */
    double pixel;                   /* mfp per pixel */
    int nx, ny;                     /* image size in pixels */
    int ntheta, nphi;               /* the scene's direction bins */
} ppb_tube_view;

/* What a pixel's ray meets first. The caps are the cuts at |z| = half_len: not a surface of
 * the infinite tube, so they carry no radiance and are drawn flat. */
enum { PPB_PIX_BACKGROUND = 0, PPB_PIX_CAP = 1, PPB_PIX_SURFACE = 2 };

typedef struct ppb_tube_hit {
    int kind;    /* PPB_PIX_* */
    int surf;    /* PPB_S1..PPB_S4 when kind is PPB_PIX_SURFACE */
    double p[3]; /* the point hit (kind != background) */
} ppb_tube_hit;

/* A camera looking along -to_cam (need not be unit; must not be parallel to +y, the world
 * "up" that fixes the image's roll), framing the clipped tube of scene sc with a margin. */
int ppb_tube_view_init(ppb_tube_view *v, const ppb_scene *sc, double half_len,
                       const double to_cam[3], int nx, int ny, ppb_err *err);

/* The two views of paper Fig. 6-7: [0] from above-left-front shows S1 and S3, [1] from
 * below-left-front shows S2 (and S3 again). */
int ppb_tube_views_paper(ppb_tube_view views[2], const ppb_scene *sc, int nx, int ny, ppb_err *err);

/* Pixel coordinates of a 3-D point. */
void ppb_tube_view_project(const ppb_tube_view *v, const double p[3], double *px, double *py);

/* The first face of the clipped tube met by the ray through pixel coordinates (px, py). */
ppb_tube_hit ppb_tube_view_hit(const ppb_tube_view *v, double px, double py);

/* Flat radiance index (ppb_cell) of what a surface hit shows: its segment along the surface
 * and the bin of the direction toward the camera in the surface's frame. */
size_t ppb_tube_view_cell(const ppb_tube_view *v, const ppb_layout *lo, const ppb_tube_hit *h);

/* Shades every pixel with r's radiance (0 off the surfaces); kind[] gets PPB_PIX_* per pixel.
 * Both arrays hold nx * ny entries, row-major from the top. r must come from the scene the view
 * was made for (its layout's bins are ntheta x nphi). */
void ppb_tube_view_render(const ppb_tube_view *v, const ppb_result *r, float *value,
                          unsigned char *kind);

#endif
