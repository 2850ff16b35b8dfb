/* experiment.h: one experiment: run every method of a config, then write the Outputs of
 * docs/reference.md (CSVs, timings, provenance, images) under the output directory.
 *
 * Computing and writing are separate so that a sweep can take the in-memory results of each
 * grid point. The Monte Carlo (`reference` in the method registry) is what rms.csv and
 * summary.csv measure against; the exact answers `mc1` (the tube's single scattering) and
 * `ppslab` (the slab) get their own summary_<id>.csv, the basis of CI's regression gate.
 * The output directory is the run's own: the set is written whole or not at all.
 *
 * A colour experiment (`[medium] channel = rgb`, docs/reference.md: Colour) runs every method
 * for the R, G and B channels (a method with run_channels once for all three) and writes one
 * grey output set per channel, <dir>/r, g, b, each exactly the set of the same config with
 * channel = r, g or b, and <dir>/y, the luminance's (every result the BT.709 weighted sum of
 * the channels', model/colour.h), beside the colour files: summary.csv and timings.csv with a
 * channel column, the linear RGB OpenEXR and sRGB PNG pictures (io/images.h). */
#ifndef PPB_EXPERIMENT_H
#define PPB_EXPERIMENT_H

#include "base/atomic_file.h"
#include "model/config.h"
#include "methods/method.h"
#include "model/result.h"
#include "drivers/provenance.h"

#define PPB_MAX_RESULTS (2 * PPB_MAX_METHODS)

/* The channel subsets of a colour experiment: r, g, b, then the luminance y. */
enum { PPB_NSUBSETS = 4, PPB_SUBSET_Y = 3 };
struct ppb_colour;

typedef struct ppb_experiment {
    const ppb_config *cfg;
    int n;
    ppb_result res[PPB_MAX_RESULTS];
    double seconds[PPB_MAX_RESULTS]; /* wall time of the method run that produced it */
    char device[512];                /* "" when no method used OpenCL */
    ppb_ocl_versions ocl_versions;   /* the device's versions (when device is not "") */
    char mc_reference[4096 + 160];   /* the reference's cache or shipped file, "" when none */
    char mc_shipped_key[64];         /* its name in the shipped layer, "" when none */
    int partial;                     /* interrupted: results are incomplete */
    /* Methods that failed at this point: no results of theirs, their reasons kept,
     * the other methods run on. */
    int nfailed;
    char failed[PPB_MAX_METHODS][32];
    char failed_why[PPB_MAX_METHODS][2048];
    /* Deterministic methods interrupted midway: none of their rows are written. */
    int nincomplete;
    char incomplete[PPB_MAX_METHODS][32];
    /* A colour experiment's channels (NULL: a grey one, whose results are the ones above; a
     * colour one has none of its own). */
    struct ppb_colour *colour;
} ppb_experiment;

/* A colour experiment's parts: each channel's config and experiment, and the luminance's
 * (its cfg the colour config itself). */
typedef struct ppb_colour {
    ppb_config cfg[3];
    ppb_experiment sub[PPB_NSUBSETS];
} ppb_colour;

/* The name of subset s ("r", "g", "b", "y"). */
const char *ppb_subset_name(int s);

/* Runs every method. A method that fails is recorded in ex->failed (and said on stderr) while
 * the others go on; fails only when no method produced a result (with the first reason). */
int ppb_experiment_compute(ppb_experiment *ex, const ppb_config *cfg, ppb_run_ctx *ctx,
                           ppb_err *err);
/* Whether dir may take an output set (a run owns its output directory, and replaces
 * it whole): it does not exist, is empty, or holds a ppbench output set (its provenance.txt
 * says so). Removes what dead processes left in and beside it (ppb_adir_clean). Fails,
 * having touched nothing, for a directory holding files ppbench did not write or one another
 * live process is writing. Callers check it before any work; ppb_experiment_write checks it
 * again. */
int ppb_experiment_claim_out(const char *dir, ppb_err *err);
/* The first line's start of a run's provenance.txt, the mark of its output set. */
extern const char ppb_provenance_mark[];
/* The claim of any command that writes a whole output set (run, mc-merge, score): dir must be
 * new, empty, or hold a set whose provenance.txt starts with "<mark>:"; never a dangling
 * symbolic link; and no other live process may hold it (an exclusive flock on .<name>.lock
 * beside it, kept until this process exits). Names its staging in ad and cleans dead
 * processes' leftovers. Fails, having touched nothing but the lock file. */
int ppb_out_claim(const char *dir, const char *mark, ppb_adir *ad, ppb_err *err);
/* Writes the outputs of the methods that ran as one set: into a staging directory beside
 * cfg->out_dir, swapped into its place when every file is written (a failure leaves the
 * previous directory as it was); then fails, naming them, if any method failed. */
int ppb_experiment_write(const ppb_experiment *ex, ppb_err *err);
void ppb_experiment_free(ppb_experiment *ex);
/* The table of drivers/summary_table.h for the results against the reference (nothing without
 * one): what `run` prints on stdout at the end. */
void ppb_experiment_print_summary(const ppb_experiment *ex, FILE *f);

/* The result every other one is measured against (mc), or NULL. */
const ppb_result *ppb_experiment_reference(const ppb_experiment *ex);

#endif
