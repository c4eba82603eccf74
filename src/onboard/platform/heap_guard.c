/* The heap guard (heap_guard.h): link-time wrappers around the C library's allocator.
 *
 * GNU ld's --wrap=sym sends every undefined reference to `sym` to `__wrap_sym`, and `__real_sym` to the
 * original; the build adds the options (FFSR_HEAP_GUARD_NEWLIB selects newlib's reentrant names). */
#include "heap_guard.h"

#include "ffsr_platform.h"

#include <stddef.h>

static int heap_locked;
static unsigned long allocation_count;
static size_t bytes_requested;
static unsigned long free_count;

void ffsr_heap_lock(void) { heap_locked = 1; }
int ffsr_heap_locked(void) { return heap_locked; }
unsigned long ffsr_heap_allocations(void) { return allocation_count; }
size_t ffsr_heap_bytes_requested(void) { return bytes_requested; }
unsigned long ffsr_heap_frees(void) { return free_count; }

/* Appends `text` at `out` (bounded by `end`); returns the new end of the text. */
static char *append_text(char *out, const char *end, const char *text) {
  while (*text != '\0' && out < end) *out++ = *text++;
  return out;
}

static char *append_unsigned(char *out, const char *end, size_t value) {
  char digits[24];
  int count = 0;
  do {
    digits[count++] = (char)('0' + (int)(value % 10u));
    value /= 10u;
  } while (value != 0u && count < (int)sizeof digits);
  while (count > 0 && out < end) *out++ = digits[--count];
  return out;
}

/* Counts one allocation, or ends the program if the heap is locked. The message is formatted by hand:
 * printf may itself allocate, and we are inside the allocator. */
static void on_allocation(const char *function, size_t bytes) {
  if (heap_locked) {
    static char message[96];
    char *const end = message + sizeof message - 1;
    char *out = append_text(message, end, "heap allocation after initialisation: ");
    out = append_text(out, end, function);
    out = append_text(out, end, "(");
    out = append_unsigned(out, end, bytes);
    out = append_text(out, end, " bytes)");
    *out = '\0';
    ffsr_platform_fatal(message, FFSR_EXIT_HEAP_AFTER_INIT);
  }
  ++allocation_count;
  bytes_requested += bytes;
}

#if defined(FFSR_HEAP_GUARD_NEWLIB)

/* newlib (-nano): every allocation ends in the _r functions; _calloc_r and _realloc_r call _malloc_r
 * themselves (and that reference is wrapped too), so a nesting depth keeps one request from being
 * counted twice. */
struct _reent;
void *__real__malloc_r(struct _reent *reent, size_t bytes);
void *__real__calloc_r(struct _reent *reent, size_t count, size_t size);
void *__real__realloc_r(struct _reent *reent, void *pointer, size_t bytes);
void *__real__memalign_r(struct _reent *reent, size_t alignment, size_t bytes);
void __real__free_r(struct _reent *reent, void *pointer);

void *__wrap__malloc_r(struct _reent *reent, size_t bytes);
void *__wrap__calloc_r(struct _reent *reent, size_t count, size_t size);
void *__wrap__realloc_r(struct _reent *reent, void *pointer, size_t bytes);
void *__wrap__memalign_r(struct _reent *reent, size_t alignment, size_t bytes);
void __wrap__free_r(struct _reent *reent, void *pointer);

static int nesting;

void *__wrap__malloc_r(struct _reent *reent, size_t bytes) {
  if (nesting == 0) on_allocation("malloc", bytes);
  return __real__malloc_r(reent, bytes);
}

void *__wrap__calloc_r(struct _reent *reent, size_t count, size_t size) {
  void *result;
  on_allocation("calloc", count * size);
  ++nesting;
  result = __real__calloc_r(reent, count, size);
  --nesting;
  return result;
}

void *__wrap__realloc_r(struct _reent *reent, void *pointer, size_t bytes) {
  void *result;
  on_allocation("realloc", bytes);
  ++nesting;
  result = __real__realloc_r(reent, pointer, bytes);
  --nesting;
  return result;
}

void *__wrap__memalign_r(struct _reent *reent, size_t alignment, size_t bytes) {
  void *result;
  on_allocation("memalign", bytes);
  ++nesting;
  result = __real__memalign_r(reent, alignment, bytes);
  --nesting;
  return result;
}

void __wrap__free_r(struct _reent *reent, void *pointer) {
  if (pointer != NULL && nesting == 0) ++free_count;
  __real__free_r(reent, pointer);
}

#else

/* glibc: the public names. glibc's calloc and realloc do not go through malloc's symbol. */
void *__real_malloc(size_t bytes);
void *__real_calloc(size_t count, size_t size);
void *__real_realloc(void *pointer, size_t bytes);
void __real_free(void *pointer);

void *__wrap_malloc(size_t bytes);
void *__wrap_calloc(size_t count, size_t size);
void *__wrap_realloc(void *pointer, size_t bytes);
void __wrap_free(void *pointer);

void *__wrap_malloc(size_t bytes) {
  on_allocation("malloc", bytes);
  return __real_malloc(bytes);
}

void *__wrap_calloc(size_t count, size_t size) {
  on_allocation("calloc", count * size);
  return __real_calloc(count, size);
}

void *__wrap_realloc(void *pointer, size_t bytes) {
  on_allocation("realloc", bytes);
  return __real_realloc(pointer, bytes);
}

void __wrap_free(void *pointer) {
  if (pointer != NULL) ++free_count;
  __real_free(pointer);
}

#endif
