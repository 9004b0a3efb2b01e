/* Prints, for each C library function the engine calls, the bits of its result on 100000 arguments
 * from a fixed pseudo-random sequence: one line "function index hex-bits" each. The same program built
 * for Linux (glibc) and for Windows (mingw-w64's C runtime) shows where the two libraries round
 * differently (tests/windows/same_bits.sh compares them). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

static uint64_t state = 88172645463325252ull; /* xorshift64 (Marsaglia 2003) */

static double uniform(double lo, double hi) {
  state ^= state << 13;
  state ^= state >> 7;
  state ^= state << 17;
  return lo + (hi - lo) * (double)(state >> 11) / 9007199254740992.0;
}

int main(void) {
  static const char* const names[] = {"exp", "sin", "cos", "atan2", "acos", "pow", "hypot", "fmod", "sqrt", "log"};
  for (int f = 0; f < 10; ++f)
    for (int i = 0; i < 100000; ++i) {
      const double x = uniform(-10.0, 10.0), y = uniform(-10.0, 10.0);
      double r;
      switch (f) {
        case 0:
          r = exp(x);
          break;
        case 1:
          r = sin(x);
          break;
        case 2:
          r = cos(x);
          break;
        case 3:
          r = atan2(y, x);
          break;
        case 4:
          r = acos(x / 10.0);
          break;
        case 5:
          r = pow(fabs(x), y);
          break;
        case 6:
          r = hypot(x, y);
          break;
        case 7:
          r = fmod(x, y);
          break;
        case 8:
          r = sqrt(fabs(x));
          break;
        default:
          r = log(fabs(x));
          break;
      }
      uint64_t bits;
      memcpy(&bits, &r, sizeof bits);
      printf("%s %d %016llx\n", names[f], i, (unsigned long long)bits);
    }
  return 0;
}
