/* Faults and hostile input driven through the command line: each test reproduces a
 * defect found on the earlier code and checks the fixed behaviour: a clear message naming the
 * file, key or option, the documented exit code (1 run failure, 2 bad input, 130 interrupted),
 * and no crash. Runs the built binary ($PPBENCH). */
#include "cliutil.h"

/* A kernel that fails to build: exit 1 with the build log, not a PoCL abort (the failure path
 * released the program and the caller released it again: exit 134/139 before). */
static void broken_kernel(const char *file, const char *methods)
{
    const char *dir = tu_scratch("broken-kernels");
    char cmd[3000], env[1200], args[3000];
    snprintf(cmd, sizeof cmd,
             "cd %s && cp --parents kernels/*.h src/methods/*/*.cl src/methods/*/*.h '%s' && "
             "echo 'this is not OpenCL C' >> '%s/%s'",
             PPB_SOURCE_DIR, dir, dir, file);
    assert_int_equal(system(cmd), 0);
    snprintf(env, sizeof env, "PPBENCH_SOURCE='%s'", dir);
    const char *p = cli_config("broken-cfg", "[mc]\nphotons = 1e4\n");
    snprintf(args, sizeof args, "run --quiet --set experiment.methods=%s --out '%s/out' '%s'",
             methods, dir, p);
    cli_expect_env(env, args, 1, "build log:");
    cli_expect_env(env, args, 1, file);
}

static void test_kernel_build_failure_march(void **state)
{
    (void)state;
    broken_kernel("src/methods/pp/march.cl", "ss");
}

static void test_kernel_build_failure_mc(void **state)
{
    (void)state;
    broken_kernel("src/methods/mc/mc.cl", "mc");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_kernel_build_failure_march),
        cmocka_unit_test(test_kernel_build_failure_mc),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
