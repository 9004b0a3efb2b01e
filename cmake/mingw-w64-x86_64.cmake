# Cross-build for x86-64 Windows with Debian's mingw-w64 (g++-mingw-w64-x86-64), as scripts/windows.sh
# uses it: cmake -DCMAKE_TOOLCHAIN_FILE=cmake/mingw-w64-x86_64.cmake ...
# The "posix" compilers: their libstdc++ has std::thread (the worker pool), on winpthreads; GCC 12's
# "win32" thread model has none.
set(CMAKE_SYSTEM_NAME Windows)
set(CMAKE_SYSTEM_PROCESSOR x86_64)
set(EMBRA_MINGW_TRIPLET x86_64-w64-mingw32)
set(CMAKE_C_COMPILER ${EMBRA_MINGW_TRIPLET}-gcc-posix)
set(CMAKE_CXX_COMPILER ${EMBRA_MINGW_TRIPLET}-g++-posix)
set(CMAKE_RC_COMPILER ${EMBRA_MINGW_TRIPLET}-windres)
# Target libraries from the mingw sysroot only; headers may also come from the host's /usr/include
# (Eigen, nlohmann-json and valijson are header-only and the same for every target), which the
# projects' find_package calls reach through CMAKE_FIND_ROOT_PATH.
set(CMAKE_FIND_ROOT_PATH /usr/${EMBRA_MINGW_TRIPLET} /usr)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE BOTH)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE BOTH)
# ctest runs the Windows programs under wine64 (tests/windows/wine.sh, with the WINEPREFIX wine/ in the build
# folder, no debug output, no display).
set(CMAKE_CROSSCOMPILING_EMULATOR ${CMAKE_CURRENT_LIST_DIR}/../tests/windows/wine.sh ${CMAKE_BINARY_DIR}/wine)
