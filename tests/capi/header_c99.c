/* embra.h alone, compiled as strict C99 with -Wall -Wextra -Wpedantic (and -Werror with
 * EMBRA_WERROR): the public header needs nothing but itself and its two generated/export
 * companions, and is valid ISO C. Nothing but the include, on purpose. */
#include "embra/embra.h"
