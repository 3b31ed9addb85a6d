// Runtime options of AddressSanitizer, LeakSanitizer and UndefinedBehaviorSanitizer, compiled
// into every program of a sanitized build (SKINLAB_SANITIZE, CMakeLists.txt). The runtimes call
// these functions at start-up; ASAN_OPTIONS, LSAN_OPTIONS and UBSAN_OPTIONS in the environment
// are applied after them, so a run can still change any option. Compiled in rather than set by
// ctest so that the test discovery at build time and the programs the CLI tests start get them
// too. docs/development.md, "Sanitizers".

#ifndef SKINLAB_SANITIZER_DIR
#error "SKINLAB_SANITIZER_DIR names tests/sanitizers (framework/CMakeLists.txt)"
#endif

#define SKINLAB_SANITIZER_API extern "C" __attribute__((visibility("default"), used))

/// ASan: stop at the first error with a symbolised stack; check the order of static
/// initialisation across our translation units.
SKINLAB_SANITIZER_API const char* __asan_default_options() {
  return "halt_on_error=1:check_initialization_order=1:strict_init_order=1:detect_leaks=1";
}

/// LSan (part of ASan): leaks of third-party libraries we cannot fix are suppressed by name in
/// lsan.supp, each with its reason.
SKINLAB_SANITIZER_API const char* __lsan_default_options() {
  return "suppressions=" SKINLAB_SANITIZER_DIR "/lsan.supp:print_suppressions=0";
}

/// UBSan: a stack trace with every finding (the build makes every finding fatal).
SKINLAB_SANITIZER_API const char* __ubsan_default_options() {
  return "print_stacktrace=1:halt_on_error=1";
}
