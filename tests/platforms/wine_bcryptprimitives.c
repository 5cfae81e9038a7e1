/* bcryptprimitives.dll for Wine 8.0 (Debian 12), which lacks it: only ProcessPrng, the one
 * function Rust's standard library imports from it (random keys for HashMap), on top of
 * RtlGenRandom (advapi32's SystemFunction036), which Wine has. Used only to run the Windows
 * build of the C API tests under Wine; every Windows 10 and later has the real DLL, and the
 * extension never ships this one. */
#include <windows.h>

BOOLEAN WINAPI SystemFunction036(PVOID buffer, ULONG length);

__declspec(dllexport) BOOL WINAPI ProcessPrng(PBYTE data, SIZE_T length) {
  while (length > 0) {
    ULONG chunk = length > 0x10000000 ? 0x10000000 : (ULONG)length;
    if (!SystemFunction036(data, chunk)) {
      return FALSE;
    }
    data += chunk;
    length -= chunk;
  }
  return TRUE;
}
