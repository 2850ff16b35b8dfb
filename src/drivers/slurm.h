/* slurm.h: `ppbench slurm`, a sweep or one experiment's Monte Carlo as a Slurm job array.
 *
 * Owns the job directory and the scripts written into it: the resolved config (config.ini),
 * the ppbench binary that every task runs (a copy), the array script (job.sh: task I runs
 * `ppbench sweep --shard I/N` or `ppbench mc-shard --shard I/N` into shards/I and then writes
 * its done marker done/I), the merge script (merge.sh: `ppbench merge` or `ppbench mc-merge`
 * into result/, once every marker is there and names this job), and job.txt, which says which
 * config, shard count and build the directory belongs to. Re-running the same command finds
 * the shards neither done nor queued in Slurm and submits only those, with a new merge job
 * after them; a directory of another config, shard count or build is refused. check.sh,
 * submitted alone (`sbatch --wait DIR/check.sh`), checks a compute node first.
 *
 * Every text is made by a pure function (tested without a cluster, tests/test_slurm.c);
 * ppb_slurm_run writes them and, with submit, calls sbatch, squeue and scancel (found on PATH).
 * The shards themselves are computed and merged by drivers/sweep.c and drivers/mc_shard.c. */
#ifndef PPB_SLURM_H
#define PPB_SLURM_H

#include <stddef.h>
#include <stdint.h>

#include "base/err.h"
#include "model/config.h"
#include "model/grid.h"

#define PPB_SLURM_BAD_CONFIG 2    /* refused before anything is written or submitted: exit 2 */
#define PPB_SLURM_MAX_SHARDS 1000 /* Slurm's default MaxArraySize is 1001 (indices 0-1000) */

typedef struct ppb_slurm_opts {
    int shards;                         /* N: array tasks, 1..PPB_SLURM_MAX_SHARDS */
    const char *partition, *time, *mem; /* #SBATCH values; NULL: the cluster's default */
    int cpus;                           /* --cpus-per-task; 0: the cluster's default */
    const char *account, *qos;          /* #SBATCH --account, --qos (every job); NULL: none */
    const char *gres;                   /* #SBATCH --gres (the array's tasks); NULL: none */
    const char *const *sbatch;          /* extra "#SBATCH <line>" lines, every job (--sbatch) */
    int nsbatch;
    const char *device; /* --device given to each task; NULL: none */
    const char *out;    /* the job directory */
    int submit;         /* 0: write the scripts and print the commands */
} ppb_slurm_opts;

typedef enum { PPB_SLURM_SWEEP, PPB_SLURM_MC } ppb_slurm_kind;

/* What the scripts are written from; ppb_slurm_run fills it, tests fill it by hand. */
typedef struct ppb_slurm_job {
    ppb_slurm_kind kind;
    int shards;
    long long units; /* sweep: grid points; mc: photons */
    char dir[1100];  /* the job directory, absolute */
    char name[160];  /* the array's Slurm job name (the merge's adds "-merge") */
    char stamp[160]; /* "<kind> shards=N config=<hash> build=<hash>": job.txt, markers */
} ppb_slurm_job;

/* Checks the #SBATCH values (they go into the scripts verbatim): --time in a form Slurm
 * reads (minutes, MM:SS, HH:MM:SS, D-HH, D-HH:MM, D-HH:MM:SS, or UNLIMITED), --mem a whole
 * number with an optional K, M, G or T, --partition, --account and --qos letters, digits, '_',
 * '-', '.' and ',', --gres the same and ':' ("gpu:a100:1"); each --sbatch line an sbatch
 * option ("--constraint=x": starting "--", printable characters only, so no newline can end the
 * line and start a command) other than those ppbench writes itself (--array, --job-name,
 * --output, --error, --dependency, --parsable). Fails naming the option. */
int ppb_slurm_check_opts(const ppb_slurm_opts *o, ppb_err *err);

/* The resolved config as INI text (malloc'd, NULL when out of memory): every key at its
 * resolved value, grouped by section in the key table's order, then each swept key with its
 * whole list in the grid's axis order (which fixes the points' order); [output] dir set to
 * out_dir. Loading it gives the same settings and grid (ppb_slurm_run checks that). */
char *ppb_slurm_config_text(const ppb_config *cfg, const ppb_grid *grid, const char *out_dir);

/* The array script and the merge script (malloc'd, NULL when out of memory). */
char *ppb_slurm_array_script(const ppb_slurm_job *job, const ppb_slurm_opts *o);
char *ppb_slurm_merge_script(const ppb_slurm_job *job, const ppb_slurm_opts *o);

/* check.sh (malloc'd, NULL when out of memory): one job with the tasks' #SBATCH lines that
 * checks what a compute node needs to run them (reference: Outputs, Slurm job directory): the
 * copied binary's shared libraries (ldd: none "not found"), the kernel sources the binary
 * reads (source_dir: kernels/ and src/methods/; $PPBENCH_SOURCE overrides it there as in
 * ppbench), and an OpenCL ICD with
 * at least one device (`ppbench devices`). Exits 0 saying "ok on NODE", else 1 naming what is
 * missing. */
char *ppb_slurm_check_script(const ppb_slurm_job *job, const ppb_slurm_opts *o,
                             const char *source_dir);

/* "1-3,5,7-8": the indices i in [1, n] with pick[i] set, as sbatch --array takes them.
 * Returns the number of indices; buf is cut (and the count still right) if too small. */
int ppb_slurm_array_spec(const unsigned char *pick, int n, char *buf, size_t cap);

/* Reads `squeue -h -r -o %i|%j|%T` output: for every line of the array's job name whose id is
 * "<job>_<task>", active[task] = 1 and its id goes to task_ids[task] (when task_ids is not NULL,
 * cap 32 each); the id of a merge job still queued (job name name + "-merge") goes to merge_id
 * ("" when none). Lines of other names are skipped. Returns the number of active tasks. */
int ppb_slurm_parse_squeue(const char *text, const char *name, int shards, unsigned char *active,
                           char (*task_ids)[32], char *merge_id, size_t merge_cap);

/* Quotes s for a POSIX shell: in single quotes, a ' written as '\''. Returns the length it
 * needs (as snprintf). */
size_t ppb_slurm_shell_quote(const char *s, char *buf, size_t cap);

/* `ppbench slurm`: prepares (or checks) the job directory o->out for cfg (a sweep when grid
 * has axes, else the config's Monte Carlo), prints the state of its shards and the commands
 * that submit the missing ones, and with o->submit submits them and a merge job after them.
 * Returns 0, -1 (a failure: I/O, sbatch), or PPB_SLURM_BAD_CONFIG. */
int ppb_slurm_run(const ppb_config *cfg, const ppb_grid *grid, const ppb_slurm_opts *o,
                  ppb_err *err);

#endif
