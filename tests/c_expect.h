#ifndef CABLESIM_TESTS_C_EXPECT_H_
#define CABLESIM_TESTS_C_EXPECT_H_

/* The C tests' one check: EXPECT(cond, printf-style message) counts a
 * failure in `failures` and prints where and why, and the test goes on. */

#include <stdio.h>

static int failures = 0;
#define EXPECT(cond, ...)                                    \
  do {                                                       \
    if (!(cond)) {                                           \
      ++failures;                                            \
      fprintf(stderr, "FAILED %s:%d: ", __FILE__, __LINE__); \
      fprintf(stderr, __VA_ARGS__);                          \
      fprintf(stderr, "\n");                                 \
    }                                                        \
  } while (0)

#endif /* CABLESIM_TESTS_C_EXPECT_H_ */
