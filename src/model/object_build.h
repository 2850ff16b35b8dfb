/* object_build.h: the three-dimensional objects' builders and readers (docs/reference.md,
 * Objects): a ppb_object (model/object.h) from a config's [object] section (box, sphere, yokan =
 * a box with a ball inclusion of a second material, a closed triangle mesh scan-converted into
 * voxels, or a voxel file), the mesh reader (Wavefront OBJ: v and f lines) and its voxeliser,
 * and the voxel file's reader and writer (a JSON header line, then the raw material bytes).
 * The object owns its arrays; ppb_object_free releases them. */
#ifndef PPB_OBJECT_BUILD_H
#define PPB_OBJECT_BUILD_H

#include "model/config.h"
#include "model/object.h"

/* The object of cfg: the grid and materials of [object] and [medium] (material 1 is [medium]'s
 * sigma_t and albedo; the object's g and n are [medium]'s), the light and camera directions,
 * [bins] theta and phi, the image and the patch size. A mesh or voxel file is read relative to
 * the config's folder; a bad one fails naming the file and the key that named it. */
int ppb_object_build(const ppb_config *cfg, ppb_object *o, ppb_err *err);
void ppb_object_free(ppb_object *o);

/* A triangle mesh: nv vertices (x, y, z) and nt triangles of three 0-based vertex indices. */
typedef struct ppb_mesh {
    int nv, nt;
    double *v;
    int *t;
} ppb_mesh;

/* Reads the v and f lines of an OBJ file (f's first index of each vertex, 1-based or negative
 * = relative; polygons fanned into triangles); other lines are skipped. */
int ppb_mesh_read_obj(const char *path, ppb_mesh *m, ppb_err *err);
void ppb_mesh_free(ppb_mesh *m);

/* Scan-converts a closed mesh into o's grid (nx, ny, nz and voxel set): the mesh scaled
 * uniformly and centred so its bounding box fits the grid's box, and a voxel is medium
 * (material mat) when its centre is inside by the parity of the crossings of a ray along +x
 * (docs/reference.md, Objects). o->mat must be allocated. */
void ppb_mesh_voxelize(const ppb_mesh *m, ppb_object *o, unsigned char mat);

/* The voxel file (docs/reference.md, Objects): one line of JSON {"format": "ppbench-voxels",
 * "version": 1, "nx", "ny", "nz", "voxel", "materials": [{"sigma_t", "albedo"}, ...]}, a
 * newline, then nx ny nz bytes of material indices in ppb_object_voxel order. */
int ppb_object_write_voxels(const ppb_object *o, const char *path, ppb_err *err);
/* Reads the grid, the voxel edge, the materials and the voxels into o (what else o holds is
 * kept); every index must name a material of the header. */
int ppb_object_read_voxels(const char *path, ppb_object *o, ppb_err *err);

#endif
