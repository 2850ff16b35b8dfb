/* cliutil.h: what the command-line suites share: run the built binary ($PPBENCH) with
 * arguments, capture its output and exit code, and write scratch configs. Header-only. */
#ifndef PPB_CLIUTIL_H
#define PPB_CLIUTIL_H

#include "testutil.h"

/* Runs `env ppbench args` (env: "" or "VAR=value ..."), stdout+stderr into out; the exit code,
 * or 128 + the signal for a killed process. */
static inline int cli_run_env(const char *env, const char *args, char *out, size_t cap)
{
    const char *bin = getenv("PPBENCH");
    size_t len = strlen(env) + strlen(args) + (bin ? strlen(bin) : 10) + 16;
    char *cmd = malloc(len);
    assert_non_null(cmd);
    snprintf(cmd, len, "%s %s %s 2>&1", env, bin ? bin : "./ppbench", args);
    FILE *p = popen(cmd, "r");
    free(cmd);
    assert_non_null(p);
    size_t n = fread(out, 1, cap - 1, p);
    out[n] = '\0';
    int st = pclose(p);
    if (WIFSIGNALED(st))
        return 128 + WTERMSIG(st);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static char cli_out[1 << 17];

/* The run must exit with `code` and print `needle`; on failure both are shown. */
static inline void cli_expect_env(const char *env, const char *args, int code, const char *needle)
{
    int rc = cli_run_env(env, args, cli_out, sizeof cli_out);
    if (rc != code || !strstr(cli_out, needle))
        fail_msg("%s ppbench %s: exit %d (want %d), output lacks '%s':\n%s", env, args, rc, code,
                 needle, cli_out);
}

static inline void cli_expect(const char *args, int code, const char *needle)
{
    cli_expect_env("", args, code, needle);
}

/* cli_config: the scratch config of testutil.h. */
#define cli_config tu_config

#endif
