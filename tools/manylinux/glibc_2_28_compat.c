/* What Debian 12's static libstdc++ and GCC 12's headers call that glibc 2.28 lacks.
 *
 * The wheel's binaries link libstdc++ statically and against glibc 2.28's symbols
 * (tools/manylinux/link.py). libstdc++.a was built against glibc 2.36, so it refers to
 * a few newer symbols; these stand in for them inside our binaries only (hidden, and
 * the link keeps them out of the dynamic symbol table). A new one shows up as an
 * undefined symbol at link time, never at a user's.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <pthread.h>
#include <stdint.h>
#include <sys/random.h>
#include <time.h>

#define HIDDEN __attribute__((visibility("hidden")))

/* glibc 2.32. Zero: "other threads may exist", so libstdc++ always uses atomic reference
 * counts, which is what it did before glibc told it otherwise. */
HIDDEN char __libc_single_threaded = 0;

/* glibc 2.36; std::random_device's default source. getrandom() is glibc 2.25. */
HIDDEN uint32_t arc4random(void) {
    uint32_t value = 0;
    while (getrandom(&value, sizeof value, 0) != (ssize_t)sizeof value) {
    }
    return value;
}

/* glibc 2.30; std::condition_variable waits on the steady clock with it. glibc 2.28 waits
 * only against CLOCK_REALTIME, so the time left on the given clock becomes a deadline on
 * the real-time clock (what libstdc++ did before pthread_cond_clockwait existed). */
HIDDEN int pthread_cond_clockwait(pthread_cond_t *cond, pthread_mutex_t *mutex, clockid_t clock,
                                  const struct timespec *deadline) {
    if (clock == CLOCK_REALTIME) {
        return pthread_cond_timedwait(cond, mutex, deadline);
    }
    if (clock != CLOCK_MONOTONIC) {
        return EINVAL;
    }
    struct timespec now, real;
    clock_gettime(clock, &now);
    clock_gettime(CLOCK_REALTIME, &real);
    int64_t left = (int64_t)(deadline->tv_sec - now.tv_sec) * 1000000000 + (deadline->tv_nsec - now.tv_nsec);
    if (left < 0) {
        left = 0;
    }
    int64_t nsec = real.tv_nsec + left % 1000000000;
    struct timespec real_deadline = {real.tv_sec + left / 1000000000 + nsec / 1000000000, nsec % 1000000000};
    return pthread_cond_timedwait(cond, mutex, &real_deadline);
}
