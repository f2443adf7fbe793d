/* Compiled into every binary of the sanitizer build (-DGODRAYS_SANITIZE=ON, CMakeLists.txt);
 * AddressSanitizer reads these before $ASAN_OPTIONS, which can still override them.
 *
 * intercept_tls_get_addr=0: GCC 12's (and LLVM <= 16's) interceptor of __tls_get_addr takes a
 * dynamic TLS block whose address is 16 bytes past a page boundary for a pre-2.19 glibc block
 * with a header, reads that "header" as a range and LeakSanitizer's tracer then dies scanning
 * it at exit ("Tracer caught signal 11 ... LeakSanitizer has encountered a fatal error"),
 * by chance of where the allocator put the block of a dlopen'ed library (Mesa's driver,
 * OpenImageIO's module). Without the interceptor the blocks are still scanned, as heap reached
 * from the thread's DTV: a leak is still reported, a pointer held in dynamic TLS is not
 * (docs/reliability.md, "Sanitizers"; tests/sanitize/dtls_leak.sh checks both). */
const char *__asan_default_options(void);
__attribute__((used, visibility("default"))) const char *__asan_default_options(void)
{
    return "intercept_tls_get_addr=0";
}
