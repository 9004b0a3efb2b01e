/* The one export macro of embra's C ABI. The library is built with hidden visibility; only
 * functions marked EMBRA_API are exported. */
#ifndef EMBRA_EMBRA_EXPORT_H
#define EMBRA_EMBRA_EXPORT_H

#if defined(_WIN32)
#if defined(EMBRA_BUILDING_LIBRARY)
#define EMBRA_API __declspec(dllexport)
#else
#define EMBRA_API __declspec(dllimport)
#endif
#elif defined(__GNUC__)
#define EMBRA_API __attribute__((visibility("default")))
#else
#define EMBRA_API
#endif

#endif /* EMBRA_EMBRA_EXPORT_H */
