/* Printing helpers of the C programs of tests/tests/c_api.rs: one line per input, result and
   failure, each number at 17 significant digits (it reads back exactly). */
#ifndef NOCDYN_TEST_REPORT_H
#define NOCDYN_TEST_REPORT_H

#include <stdint.h>
#include <stdio.h>

/* `in LABEL v...`: an input the Rust side feeds to the same function. */
static inline void input(const char *label, const double *v, int n) {
    int i;
    printf("in %s", label);
    for (i = 0; i < n; i++) printf(" %.17g", v[i]);
    printf("\n");
}

/* `out LABEL STATUS v...`: a function's status and, on success, its outputs in order. */
static inline void output(const char *label, int32_t status, const double *v, int n) {
    int i;
    printf("out %s %d", label, (int)status);
    if (status == 0)
        for (i = 0; i < n; i++) printf(" %.17g", v[i]);
    printf("\n");
}

/* `err LABEL STATUS INDEX COLUMN ITERATIONS VALUE CONDITION`: a failure and its report. */
static inline void failure(const char *label, int32_t status, int32_t index, int32_t column,
                           int32_t iterations, double value, double condition) {
    printf("err %s %d %d %d %d %.17g %.17g\n", label, (int)status, (int)index, (int)column,
           (int)iterations, value, condition);
}

#endif
