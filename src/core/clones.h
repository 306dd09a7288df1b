/* ATMOS_CLONES: placed before a function's definition, it builds the function twice, for AVX2
 * and for the baseline, and the loader picks the best for the CPU at run time (an ifunc). It
 * stands for nothing, and the function is built once for the baseline, where that cannot
 * work: a compiler other than GCC or Clang 16 or later, a target other than x86-64, a C
 * library without ifunc resolvers (only glibc and FreeBSD's have them; musl, macOS and
 * Windows do not), or a build with AddressSanitizer (a resolver runs before the sanitizer's
 * run time is set up).
 * -DATMOS_NO_CLONES leaves the clones out on any platform. Helpers that a cloned function
 * calls are inlined into each clone (always_inline), or they are built for the baseline only. */
#ifndef ATMOS_CORE_CLONES_H
#define ATMOS_CORE_CLONES_H

#include <limits.h> /* defines __GLIBC__ where the C library is glibc */

#if defined(__has_feature)
#  if __has_feature(address_sanitizer)
#    define ATMOS_CLONES_ASAN 1
#  endif
#endif
#if defined(__SANITIZE_ADDRESS__)
#  define ATMOS_CLONES_ASAN 1
#endif

/* Clang before 16 names a cloned function's ifunc "f.ifunc", which other files' calls to f do
 * not find (and gives two static clones of one name one global resolver): baseline there. */
#if defined(__clang__) && __clang_major__ < 16
#  define ATMOS_CLONES_OLD_CLANG 1
#endif

#if !defined(ATMOS_NO_CLONES) && !defined(ATMOS_CLONES_ASAN) && !defined(ATMOS_CLONES_OLD_CLANG) &&  \
    defined(__GNUC__) && defined(__x86_64__) && (defined(__GLIBC__) || defined(__FreeBSD__)) &&    \
    defined(__has_attribute)
#  if __has_attribute(target_clones)
#    define ATMOS_CLONES __attribute__((target_clones("avx2", "default")))
#    define ATMOS_HAVE_CLONES 1
#  endif
#endif
#ifndef ATMOS_CLONES
#  define ATMOS_CLONES
#endif

/* ATMOS_CLONES on a function that is never inlined into its callers. Clang refuses noinline
 * beside target_clones; it never inlines a cloned function anyway (the calls go through the
 * resolver). */
#if defined(ATMOS_HAVE_CLONES) && defined(__clang__)
#  define ATMOS_CLONES_NOINLINE ATMOS_CLONES
#elif defined(__GNUC__)
#  define ATMOS_CLONES_NOINLINE ATMOS_CLONES __attribute__((noinline))
#else
#  define ATMOS_CLONES_NOINLINE
#endif

/* ATMOS_CLONE_HELPER: a static helper of a cloned function, always inlined, so that each clone
 * holds its own copy built for the clone's instructions (a call would reach the baseline copy). */
#if defined(__GNUC__)
#  define ATMOS_CLONE_HELPER static inline __attribute__((always_inline))
#else
#  define ATMOS_CLONE_HELPER static inline
#endif

#endif
