#include "drivers/study_guard.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/atomic_file.h"

#ifndef PPB_SOURCE_DIR
#define PPB_SOURCE_DIR "."
#endif

const char *ppb_source_dir(void)
{
    const char *d = getenv("PPBENCH_SOURCE");
    return d && *d ? d : PPB_SOURCE_DIR;
}

/* The real path of path's parent directory (path need not exist): 0, or -1 when the parent
 * does not exist (then no study directory can be meant). */
static int real_parent(const char *path, char *buf)
{
    char copy[PPB_PATH_MAX];
    snprintf(copy, sizeof copy, "%s", path);
    size_t n = strlen(copy);
    while (n > 1 && copy[n - 1] == '/')
        copy[--n] = '\0';
    char *slash = strrchr(copy, '/');
    if (!slash)
        snprintf(copy, sizeof copy, ".");
    else if (slash == copy)
        copy[1] = '\0';
    else
        *slash = '\0';
    return realpath(copy, buf) ? 0 : -1;
}

/* Whether the last component of path is a case of <source>/configs/<list>. */
static int study_case(const char *path, const char *list_name)
{
    char name[256], list[PPB_PATH_MAX + 32], line[256];
    size_t n = strlen(path);
    while (n > 1 && path[n - 1] == '/')
        n--;
    size_t b = n;
    while (b > 0 && path[b - 1] != '/')
        b--;
    snprintf(name, sizeof name, "%.*s", (int)(n - b), path + b);
    snprintf(list, sizeof list, "%.4000s/configs/%s", ppb_source_dir(), list_name);
    FILE *f = fopen(list, "r");
    int found = 0;
    while (f && !found && fgets(line, sizeof line, f)) {
        line[strcspn(line, "\r\n")] = '\0';
        found = line[0] && strcmp(line, name) == 0;
    }
    if (f)
        fclose(f);
    return found;
}

int ppb_study_guard(const char *out_dir, ppb_err *err)
{
    const char *mark = getenv("PPB_BENCH_STUDY");
    if (mark && strcmp(mark, "1") == 0)
        return 0;
    char results[PPB_PATH_MAX + 16], real[PATH_MAX], parent[PATH_MAX], self[PATH_MAX];
    snprintf(results, sizeof results, "%.4000s/results", ppb_source_dir());
    if (!realpath(results, real))
        return 0; /* no committed study here */
    /* and the materials study's: results/materials/<case of configs/materials.list> */
    char materials[PATH_MAX + 16];
    snprintf(materials, sizeof materials, "%s/materials", real);
    int has_parent = real_parent(out_dir, parent) == 0;
    int is_study =
        (realpath(out_dir, self) && strcmp(self, real) == 0) ||
        (has_parent && strcmp(parent, real) == 0 && study_case(out_dir, "study.list")) ||
        (has_parent && strcmp(parent, materials) == 0 && study_case(out_dir, "materials.list"));
    if (!is_study)
        return 0;
    return ppb_fail(err,
                    "output directory %s is the committed study's (%s), which only `make bench` "
                    "writes: give --out DIR",
                    out_dir, real);
}
