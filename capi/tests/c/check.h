/* The C tests' one check: prints the failed condition, the values and
   the crate's last error, and counts it (main returns 1 when any failed). */
#ifndef GUIDING_TEST_CHECK_H
#define GUIDING_TEST_CHECK_H

#include "guiding.h"

#include <stdio.h>

static int failures = 0;

#define CHECK(cond, ...)                                                   \
    do {                                                                   \
        if (!(cond)) {                                                     \
            fprintf(stderr, "%s:%d: %s: ", __FILE__, __LINE__, #cond);     \
            fprintf(stderr, __VA_ARGS__);                                  \
            fprintf(stderr, " (last error: %s)\n", guiding_last_error());  \
            failures++;                                                    \
        }                                                                  \
    } while (0)

#define OK(call) CHECK((call) == GUIDING_STATUS_OK, "%s", "not OK")

#endif
