/* study_score.h: `ppbench study-score`: methods scored on every case of the study
 * (configs/study.list) against the shipped or cached Monte Carlo reference, and the study's
 * report over them (docs/reference.md: Outputs, "study-score"; docs/external.md).
 *
 * Each case is one `ppbench run` of this binary (a child process: the run's own checks,
 * writers and failure handling) with experiment.methods = mc plus the methods scored, into
 * OUT/<case>; its environment carries PPBENCH_MC_NO_TRACE=1 (unless the caller set it), so a
 * case whose reference is neither cached nor shipped fails instead of tracing. The committed
 * study's rows of other methods (results/<case>/summary.csv, rms.csv) are added beside them when
 * that set's reference is the same file (its provenance.txt's mc.reference names the same key),
 * and `ppbench report OUT CASE...` writes table2.csv/.md and README.md. */
#ifndef PPB_STUDY_SCORE_H
#define PPB_STUDY_SCORE_H

typedef struct ppb_study_score_opts {
    const char *methods;      /* --methods a,b; NULL: the CONFIG's [method.NAME] sections */
    const char *radiance_dir; /* --radiance-dir DIR: DIR/<case>.csv or DIR/<case>/radiance.csv */
    const char *out;          /* --out DIR; NULL: ./study-score */
    const char *config;       /* CONFIG whose [method.NAME] sections define external methods */
    const char *const *sets;  /* --set, passed to every case */
    int nsets;
    const char *ref_cache; /* --ref-cache DIR, or NULL */
    int no_ref_cache, quiet;
    const char *device;
} ppb_study_score_opts;

/* Exit code: 0, 1 (a case failed), 2 (bad command line, config or input), 130. */
int ppb_study_score_main(const ppb_study_score_opts *o);

#endif
