// embra.h alone, compiled as C++ with -Wall -Wextra -Wpedantic (and -Werror with EMBRA_WERROR):
// a C++ host can include the C ABI header directly. Nothing but the include, on purpose.
#include "embra/embra.h"
