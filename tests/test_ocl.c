/* The OpenCL layer on PoCL: device choice, error names, build logs, and a kernel that evaluates
 * the shared conventions header (expected values: the same functions evaluated on the host). */
#include "testutil.h"

#include "runtime/ocl.h"

static void test_error_names(void **state)
{
    (void)state;
    assert_string_equal(ppb_cl_errname(CL_BUILD_PROGRAM_FAILURE), "CL_BUILD_PROGRAM_FAILURE");
    assert_string_equal(ppb_cl_errname(CL_OUT_OF_RESOURCES), "CL_OUT_OF_RESOURCES");
    ppb_err err = {{0}};
    assert_int_equal(ppb_cl_check(CL_INVALID_KERNEL_ARGS, "clEnqueueNDRangeKernel", &err), -1);
    assert_non_null(strstr(err.msg, "clEnqueueNDRangeKernel failed: CL_INVALID_KERNEL_ARGS"));
}

static void test_choose_device(void **state)
{
    (void)state;
    ppb_err err = {{0}};
    ppb_ocl ocl;
    assert_int_equal(ppb_ocl_open(&ocl, "0", &err), 0);
    char name[512];
    snprintf(name, sizeof name, "%s", ocl.name);
    ppb_ocl_close(&ocl);
    /* A substring of the listed name picks the same device, whatever its case. */
    char sub[8];
    snprintf(sub, sizeof sub, "%.4s", strstr(name, "/ ") ? strstr(name, "/ ") + 2 : name);
    for (char *c = sub; *c; c++)
        *c = (char)((*c >= 'a' && *c <= 'z') ? *c - 32 : *c);
    assert_int_equal(ppb_ocl_open(&ocl, sub, &err), 0);
    assert_string_equal(ocl.name, name);
    ppb_ocl_close(&ocl);
    assert_int_equal(ppb_ocl_open(&ocl, "99", &err), -1);
    assert_non_null(strstr(err.msg, "--device 99: no such device"));
    assert_int_equal(ppb_ocl_open(&ocl, "no-such-device-xyz", &err), -1);
    assert_non_null(strstr(err.msg, "no device name contains it"));
}

static void test_build_log(void **state)
{
    (void)state;
    const char *dir = tu_scratch("ocl-build");
    char path[1200];
    snprintf(path, sizeof path, "%s/broken.cl", dir);
    FILE *f = fopen(path, "w");
    fputs("__kernel void k(__global int *a) { a[0] = undefined_symbol; }\n", f);
    fclose(f);
    setenv("PPBENCH_SOURCE", dir, 1);
    ppb_err err = {{0}};
    ppb_ocl ocl;
    assert_int_equal(ppb_ocl_open(&ocl, NULL, &err), 0);
    cl_program prog;
    assert_int_equal(ppb_ocl_build(&ocl, "broken.cl", NULL, &prog, &err), -1);
    assert_non_null(strstr(err.msg, "CL_BUILD_PROGRAM_FAILURE"));
    assert_non_null(strstr(err.msg, "undefined_symbol")); /* the compiler's log is included */
    assert_int_equal(ppb_ocl_build(&ocl, "missing.cl", NULL, &prog, &err), -1);
    assert_non_null(strstr(err.msg, "missing.cl: cannot open kernel source"));
    unsetenv("PPBENCH_SOURCE");
    ppb_ocl_close(&ocl);
}

#define N 4096

static void test_kernel_matches_host(void **state)
{
    (void)state;
    static double mu[N], wt[N], wb[N];
    static int tb[N], pb[N];
    for (int i = 0; i < N; i++) { /* directions spread over the hemisphere, edges included */
        double s2 = (double)(i % 64) / 63.0, phi = PPB_PI * (double)(i / 64) / 63.0;
        mu[i] = sqrt(1 - s2);
        wt[i] = sqrt(s2) * cos(phi);
        wb[i] = (i % 2 ? -1 : 1) * sqrt(s2) * sin(phi);
    }
    ppb_err err = {{0}};
    ppb_ocl ocl;
    assert_int_equal(ppb_ocl_open(&ocl, NULL, &err), 0);
    cl_program prog;
    if (ppb_ocl_build(&ocl, "tests/kernels/selftest.cl", NULL, &prog, &err))
        fail_msg("%s", err.msg);
    cl_kernel k;
    assert_int_equal(ppb_ocl_kernel(prog, "bins_of", &k, &err), 0);
    cl_int rc;
    cl_mem b[5];
    const size_t dsz = sizeof(double) * N, isz = sizeof(int) * N;
    b[0] = clCreateBuffer(ocl.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, dsz, mu, &rc);
    b[1] = clCreateBuffer(ocl.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, dsz, wt, &rc);
    b[2] = clCreateBuffer(ocl.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, dsz, wb, &rc);
    b[3] = clCreateBuffer(ocl.context, CL_MEM_WRITE_ONLY, isz, NULL, &rc);
    b[4] = clCreateBuffer(ocl.context, CL_MEM_WRITE_ONLY, isz, NULL, &rc);
    assert_int_equal(rc, CL_SUCCESS);
    cl_int nt = 8, np = 8;
    for (int i = 0; i < 5; i++)
        clSetKernelArg(k, (cl_uint)i, sizeof(cl_mem), &b[i]);
    clSetKernelArg(k, 5, sizeof nt, &nt);
    clSetKernelArg(k, 6, sizeof np, &np);
    size_t global = N;
    assert_int_equal(clEnqueueNDRangeKernel(ocl.queue, k, 1, NULL, &global, NULL, 0, NULL, NULL),
                     CL_SUCCESS);
    clEnqueueReadBuffer(ocl.queue, b[3], CL_TRUE, 0, isz, tb, 0, NULL, NULL);
    clEnqueueReadBuffer(ocl.queue, b[4], CL_TRUE, 0, isz, pb, 0, NULL, NULL);
    for (int i = 0; i < N; i++) {
        assert_int_equal(tb[i], ppb_theta_bin(mu[i], 8));
        assert_int_equal(pb[i], ppb_phi_bin(wt[i], wb[i], 8));
    }
    for (int i = 0; i < 5; i++)
        clReleaseMemObject(b[i]);
    clReleaseKernel(k);
    clReleaseProgram(prog);
    ppb_ocl_close(&ocl);
}

static void test_list(void **state)
{
    (void)state;
    ppb_err err = {{0}};
    FILE *f = tmpfile();
    assert_in_range(ppb_ocl_list(f, &err), 1, 1000);
    fclose(f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_error_names),         cmocka_unit_test(test_list),
        cmocka_unit_test(test_choose_device),       cmocka_unit_test(test_build_log),
        cmocka_unit_test(test_kernel_matches_host),
    };
    return cmocka_run_group_tests_name("ocl", tests, NULL, NULL);
}
