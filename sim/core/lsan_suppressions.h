// LeakSanitizer's built-in suppressions for the sanitizer build (SHELLMPM_SANITIZE):
// Mesa's OSMesa keeps per-thread GL dispatch state that OSMesaMakeCurrent allocates and
// OSMesaDestroyContext does not free (480 bytes in 5 blocks, all inside libOSMesa.so).
// LSan asks the program for this list before main; include this header in exactly one
// translation unit of each executable.
#pragma once
#ifdef SHELLMPM_SANITIZE
extern "C" const char* __lsan_default_suppressions() {  // NOLINT: LSan's hook name
  return "leak:libOSMesa.so\n";
}
#endif
