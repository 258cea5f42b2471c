#pragma once
// GT_API marks what the shared library exports: the library is built with hidden visibility,
// so everything else (the internal stages in host/src) stays inside it.

#if defined(_WIN32)
#define GT_API
#else
#define GT_API __attribute__((visibility("default")))
#endif
