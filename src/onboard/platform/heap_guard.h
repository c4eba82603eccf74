/* The heap guard: proves that a program's steady state does not allocate.
 *
 * The program allocates what it needs during initialisation, then calls ffsr_heap_lock(). From then on
 * any allocation (malloc, calloc, realloc, and everything built on them: operator new, Eigen's dynamic
 * matrices, stdio's lazily allocated buffers) prints one line
 *     ffsr: heap allocation after initialisation: <function>(<bytes> bytes)
 * and ends the program with FFSR_EXIT_HEAP_AFTER_INIT (ffsr_platform.h). free() stays allowed: releasing
 * the initialisation's memory at shutdown is fine.
 *
 * It works by link-time wrapping (GNU ld --wrap), so the program needs no changes beyond the lock call;
 * the build (src/onboard/CMakeLists.txt) adds the options to every program that links the platform:
 *  - Linux (glibc): --wrap=malloc,--wrap=calloc,--wrap=realloc,--wrap=free. With the static aarch64
 *    link this also catches glibc's own calls (stdio's buffers); with the host's shared libc only the
 *    program's and its static libraries' calls are seen.
 *  - Cortex-M7 (newlib-nano): newlib's stdio calls the reentrant _malloc_r family directly, and malloc,
 *    calloc, realloc and free are one-line wrappers around them (separate archive members, so the
 *    references are wrappable): the guard wraps _malloc_r, _calloc_r, _realloc_r, _memalign_r and
 *    _free_r, which every path goes through, operator new included.
 *
 * Mind stdio: a stream's buffer is allocated on its first use (and newlib's fopen may allocate its FILE
 * table). Open the output files and give every stream used after the lock a buffer of its own with
 * setvbuf before locking (see examples/onboard/onboard_example.c); newlib's printf of a floating-point
 * value also allocates (its dtoa), so print only integers and strings after the lock.
 *
 * Single-threaded by design (the onboard core runs on one thread); not async-signal-safe.
 */
#ifndef FFSR_ONBOARD_HEAP_GUARD_H
#define FFSR_ONBOARD_HEAP_GUARD_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Initialisation is over: every later allocation is fatal. */
void ffsr_heap_lock(void);

/* 1 once ffsr_heap_lock() has been called. */
int ffsr_heap_locked(void);

/* Allocations (calls that returned or would return new memory: malloc, calloc, realloc, memalign) and
 * bytes requested since the program started; all of them before the lock, since one after it is fatal. */
unsigned long ffsr_heap_allocations(void);
size_t ffsr_heap_bytes_requested(void);

/* Calls of free (with a non-null pointer) since the program started. */
unsigned long ffsr_heap_frees(void);

#ifdef __cplusplus
}
#endif

#endif /* FFSR_ONBOARD_HEAP_GUARD_H */
