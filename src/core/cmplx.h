/* <complex.h> with C11's CMPLX (7.3.9.3), which glibc's header defines for GCC only; Clang has
 * the builtin it stands for. */
#ifndef ATMOS_CORE_CMPLX_H
#define ATMOS_CORE_CMPLX_H

#include <complex.h>

#ifndef CMPLX
#define CMPLX(x, y) __builtin_complex((double)(x), (double)(y))
#endif

#endif
