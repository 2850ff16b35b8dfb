/* ppb_object.h: the three-dimensional objects' conventions (docs/reference.md, Objects), for the
 * host (model/object_build.c, the object methods, the `ppbench object` driver) and the object
 * kernels (methods/mc3d/mc3d.cl).
 *
 * Owns: a direction from (theta from +y, phi from +x toward +z), a boundary face's index in the
 * face-to-patch table, the direction bin of an exit in a patch's frame (theta bins of equal
 * projected solid angle as the tube's, phi over the whole [0, 2 pi) from t toward b = n x t),
 * the bins' projected solid angle, and the orthographic camera's frame, image extent and pixel
 * of a point. Plain C that is also OpenCL C; nothing here allocates. */
#ifndef PPB_OBJECT_CONV_H
#define PPB_OBJECT_CONV_H

#include "ppb_conventions.h"

/* The unit vector at theta degrees from +y and phi degrees from +x toward +z: the direction
 * toward the light or the camera ([object] light_theta, camera_theta, ...). */
PPB_FN void ppb_obj_dir(double theta_deg, double phi_deg, double *w)
{
    double t = theta_deg * (PPB_PI / 180.0), p = phi_deg * (PPB_PI / 180.0);
    w[0] = sin(t) * cos(p);
    w[1] = cos(t);
    w[2] = sin(t) * sin(p);
}

/* Face f of a voxel, f = 2 axis + (side > 0): its slot in ppb_object_patches.face_patch. */
PPB_FN int ppb_obj_face(int axis, int side)
{
    return 2 * axis + (side > 0);
}

/* A patch's frame from its axis and side (model/object.c): n = side e_axis, t = e_u with
 * u = (axis + 1) mod 3, b = n x t = side e_v with v = (axis + 2) mod 3. The bin of an outgoing
 * direction w (w.n > 0): theta as the tube's (ppb_theta_bin, equal sin^2 theta), phi =
 * atan2(w.b, w.t) in [0, 2 pi) in nphi equal bins; bin = itheta nphi + iphi. */
PPB_FN int ppb_obj_bin(int axis, int side, double wx, double wy, double wz, int ntheta, int nphi)
{
    double w[3] = {wx, wy, wz};
    int u = (axis + 1) % 3, v = (axis + 2) % 3;
    double mu = side * w[axis], wt = w[u], wb = side * w[v];
    double phi = atan2(wb, wt);
    if (phi < 0)
        phi += 2.0 * PPB_PI;
    int k = (int)(phi * (0.5 / PPB_PI) * nphi);
    k = k < 0 ? 0 : (k >= nphi ? nphi - 1 : k);
    return ppb_bin_index(ppb_theta_bin(mu, ntheta), k, nphi);
}

/* Projected solid angle of every object bin: the hemisphere's pi over ntheta nphi bins (each
 * theta bin holds pi / ntheta, each phi bin an equal share of it). */
PPB_FN double ppb_obj_bin_proj_solid_angle(int ntheta, int nphi)
{
    return PPB_PI / (ntheta * nphi);
}

/* The orthographic camera (docs/reference.md, Objects). c is the unit direction toward the
 * camera; the camera looks along f = -c. Its image axes: right r = normalise(f x up) and
 * up' = r x f, with up = +y, or +z when c is within about 2.6 degrees of the y axis
 * (|c_y| > 0.999), where f x y degenerates. */
typedef struct ppb_obj_camera {
    double c[3], r[3], u[3]; /* toward the camera, image right, image up */
    double r0, u1;           /* the image's left edge along r and top edge along u */
    double pixel;            /* square pixel edge */
    int w, h;
} ppb_obj_camera;

/* The camera of direction c whose w x h square pixels cover the projection of the box
 * [0, ex] x [0, ey] x [0, ez] (the object's grid), centred: pixel = the larger of the box's
 * extents along r and u' over w and h. */
PPB_FN ppb_obj_camera ppb_obj_camera_make(const double *c, double ex, double ey, double ez, int w,
                                          int h)
{
    ppb_obj_camera cam;
    double f[3] = {-c[0], -c[1], -c[2]};
    double up[3] = {0.0, 1.0, 0.0};
    if (fabs(c[1]) > 0.999)
        up[1] = 0.0, up[2] = 1.0;
    double r[3] = {f[1] * up[2] - f[2] * up[1], f[2] * up[0] - f[0] * up[2],
                   f[0] * up[1] - f[1] * up[0]};
    double rl = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    for (int k = 0; k < 3; k++)
        cam.c[k] = c[k], cam.r[k] = r[k] / rl;
    cam.u[0] = cam.r[1] * f[2] - cam.r[2] * f[1];
    cam.u[1] = cam.r[2] * f[0] - cam.r[0] * f[2];
    cam.u[2] = cam.r[0] * f[1] - cam.r[1] * f[0];
    double rmin = 1e300, rmax = -1e300, umin = 1e300, umax = -1e300;
    for (int k = 0; k < 8; k++) {
        double p[3] = {(k & 1) ? ex : 0.0, (k & 2) ? ey : 0.0, (k & 4) ? ez : 0.0};
        double pr = p[0] * cam.r[0] + p[1] * cam.r[1] + p[2] * cam.r[2];
        double pu = p[0] * cam.u[0] + p[1] * cam.u[1] + p[2] * cam.u[2];
        rmin = fmin(rmin, pr), rmax = fmax(rmax, pr);
        umin = fmin(umin, pu), umax = fmax(umax, pu);
    }
    cam.pixel = fmax((rmax - rmin) / w, (umax - umin) / h);
    cam.r0 = 0.5 * (rmin + rmax) - 0.5 * w * cam.pixel;
    cam.u1 = 0.5 * (umin + umax) + 0.5 * h * cam.pixel;
    cam.w = w, cam.h = h;
    return cam;
}

/* The pixel (row-major from the top-left) that point p projects to, or -1 outside the image.
 * Every point of a ray toward the camera projects to the same pixel. */
PPB_FN long ppb_obj_camera_pixel(const ppb_obj_camera *cam, double px, double py, double pz)
{
    double pr = px * cam->r[0] + py * cam->r[1] + pz * cam->r[2];
    double pu = px * cam->u[0] + py * cam->u[1] + pz * cam->u[2];
    double col = floor((pr - cam->r0) / cam->pixel), row = floor((cam->u1 - pu) / cam->pixel);
    if (col < 0 || row < 0 || col >= cam->w || row >= cam->h)
        return -1;
    return (long)row * cam->w + (long)col;
}

#endif
