/* Newlib system calls for a heap-free target. Output goes to semihosting; every way to get heap
 * memory fails loudly: _sbrk, and malloc/calloc/realloc/free wrapped at link time
 * (-Wl,--wrap=...). abort() and traps end the program with a distinct exit code. */
#include <errno.h>
#include <stddef.h>
#include <stdint.h>
#include <sys/stat.h>

#include "arbor_target.h"

static __attribute__((noreturn)) void heap_trap(const char* what) {
  arbor_puts("\n*** heap allocation on a heap-free target: ");
  arbor_puts(what);
  arbor_puts(" ***\n");
  arbor_exit(ARBOR_EXIT_HEAP);
}

void* _sbrk(ptrdiff_t increment) {
  (void)increment;
  heap_trap("_sbrk");
}

void* __wrap_malloc(size_t n) {
  (void)n;
  heap_trap("malloc");
}
void* __wrap_calloc(size_t n, size_t m) {
  (void)n;
  (void)m;
  heap_trap("calloc");
}
void* __wrap_realloc(void* p, size_t n) {
  (void)p;
  (void)n;
  heap_trap("realloc");
}
void __wrap_free(void* p) {
  if (p)
    heap_trap("free");
}
void* __wrap__malloc_r(void* reent, size_t n) {
  (void)reent;
  (void)n;
  heap_trap("_malloc_r");
}

void abort(void) {
  arbor_puts("\n*** abort() ***\n");
  arbor_exit(ARBOR_EXIT_ABORT);
}

void _exit(int code) {
  arbor_exit(code);
}

int _write(int fd, const char* buf, int len) {
  (void)fd;
  char chunk[129];
  int done = 0;
  while (done < len) {
    int n = len - done < 128 ? len - done : 128;
    for (int i = 0; i < n; ++i)
      chunk[i] = buf[done + i];
    chunk[n] = 0;
    arbor_puts(chunk);
    done += n;
  }
  return len;
}

int _read(int fd, char* buf, int len) {
  (void)fd;
  (void)buf;
  (void)len;
  errno = ENOSYS;
  return -1;
}
int _close(int fd) {
  (void)fd;
  return -1;
}
int _fstat(int fd, struct stat* st) {
  (void)fd;
  st->st_mode = S_IFCHR;
  return 0;
}
int _isatty(int fd) {
  (void)fd;
  return 1;
}
int _lseek(int fd, int off, int whence) {
  (void)fd;
  (void)off;
  (void)whence;
  return 0;
}
int _kill(int pid, int sig) {
  (void)pid;
  (void)sig;
  errno = EINVAL;
  return -1;
}
int _getpid(void) {
  return 1;
}
