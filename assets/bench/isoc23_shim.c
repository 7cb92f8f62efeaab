/* pyvcad 2.3.4's wheel (tagged manylinux_2_28) calls glibc 2.38's C23
 * parsing functions; on an older glibc (Debian 12 has 2.36) they are
 * missing and `import pyvcad` fails with "undefined symbol:
 * __isoc23_strtoll". These forward to the classic functions, which differ
 * only in accepting a "0b" prefix, which pyvcad's number parsing of the
 * benchmark designs never meets. Only for the benchmark (README.md here):
 *
 *   cc -shared -fPIC -O2 -o /tmp/libisoc23.so assets/bench/isoc23_shim.c
 *   PYVCAD_PRELOAD=/tmp/libisoc23.so PYVCAD_PYTHON=/tmp/pyvcad/bin/python \
 *     python3 assets/bench/vs_pyvcad.py
 */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

long __isoc23_strtol(const char *s, char **e, int b) { return strtol(s, e, b); }
long long __isoc23_strtoll(const char *s, char **e, int b) { return strtoll(s, e, b); }
unsigned long __isoc23_strtoul(const char *s, char **e, int b) { return strtoul(s, e, b); }
unsigned long long __isoc23_strtoull(const char *s, char **e, int b) { return strtoull(s, e, b); }
int __isoc23_sscanf(const char *s, const char *f, ...) {
    va_list a;
    va_start(a, f);
    int r = vsscanf(s, f, a);
    va_end(a);
    return r;
}
