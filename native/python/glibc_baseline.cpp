// glibc_baseline.cpp — keeps the module loadable on glibc 2.28 (Blender's Linux baseline).
//
// The module links libstdc++ statically (it then needs no libstdc++ of a given
// age), and this machine's glibc is newer than Blender's baseline, so some of
// the static libstdc++'s references would bind to symbol versions newer than
// 2.28. The link wraps them (-Wl,--wrap=NAME, CMakeLists.txt) and the wrappers
// here call what every glibc since 2.2.5 exports:
//  - pthread_create/join/detach/once, __pthread_key_create: glibc 2.34 moved
//    libpthread into libc and gave them new versions; the 2.2.5 versions stay;
//  - fstat (2.33: before, glibc exported only __fxstat, the header called it
//    with _STAT_VER = 1 on x86-64): the wrapper calls __fxstat@2.2.5;
//  - arc4random (2.36): only std::random_device uses it, which the module never
//    constructs; the wrapper reads getrandom (2.25) instead;
//  - __libc_single_threaded (2.32, libstdc++'s "single threaded?" shortcut): a
//    hidden definition here wins over glibc's. Its value 0 means "maybe
//    threaded": libstdc++ always takes its atomic paths — correct on any glibc.
// The unwinder comes from the shared libgcc_s (every Linux has it), whose
// static copy would ask for _dl_find_object (2.35).
// tests/python/test_module_portable.py reads the module's dynamic symbol table.
#include <pthread.h>
#include <sys/random.h>
#include <sys/stat.h>

#include <cstdint>

extern "C" {

__attribute__((visibility("hidden"))) char __libc_single_threaded = 0;

#define CG_OLD_SYMBOL(local, name) __asm__(".symver " #local ", " #name "@GLIBC_2.2.5")

int cg_pthread_create_2_2_5(pthread_t*, const pthread_attr_t*, void* (*)(void*), void*);
int cg_pthread_join_2_2_5(pthread_t, void**);
int cg_pthread_detach_2_2_5(pthread_t);
int cg_pthread_once_2_2_5(pthread_once_t*, void (*)(void));
int cg_pthread_key_create_2_2_5(pthread_key_t*, void (*)(void*));
CG_OLD_SYMBOL(cg_pthread_create_2_2_5, pthread_create);
CG_OLD_SYMBOL(cg_pthread_join_2_2_5, pthread_join);
CG_OLD_SYMBOL(cg_pthread_detach_2_2_5, pthread_detach);
CG_OLD_SYMBOL(cg_pthread_once_2_2_5, pthread_once);
CG_OLD_SYMBOL(cg_pthread_key_create_2_2_5, __pthread_key_create);
int cg_fxstat_2_2_5(int version, int fd, struct stat* buf);
CG_OLD_SYMBOL(cg_fxstat_2_2_5, __fxstat);

#define CG_HIDDEN __attribute__((visibility("hidden")))

CG_HIDDEN int __wrap_pthread_create(pthread_t* t, const pthread_attr_t* a, void* (*f)(void*), void* arg) {
  return cg_pthread_create_2_2_5(t, a, f, arg);
}
CG_HIDDEN int __wrap_pthread_join(pthread_t t, void** result) { return cg_pthread_join_2_2_5(t, result); }
CG_HIDDEN int __wrap_pthread_detach(pthread_t t) { return cg_pthread_detach_2_2_5(t); }
CG_HIDDEN int __wrap_pthread_once(pthread_once_t* once, void (*f)(void)) { return cg_pthread_once_2_2_5(once, f); }
CG_HIDDEN int __wrap___pthread_key_create(pthread_key_t* key, void (*destructor)(void*)) {
  return cg_pthread_key_create_2_2_5(key, destructor);
}

CG_HIDDEN int __wrap_fstat(int fd, struct stat* buf) { return cg_fxstat_2_2_5(1 /* _STAT_VER */, fd, buf); }

CG_HIDDEN std::uint32_t __wrap_arc4random(void) {
  std::uint32_t v = 0;
  while (getrandom(&v, sizeof v, 0) != static_cast<ssize_t>(sizeof v)) {
  }
  return v;
}

}  // extern "C"
