# Initial cache for the libFuzzer build of vrlcuts (cmake -C fuzz/clang-fuzz.cmake):
# clang, libFuzzer + AddressSanitizer + UndefinedBehaviorSanitizer, only the
# libraries the fuzzers need and the fuzz executables (VRL_FUZZ_ONLY).
# fuzz/CMakeLists.txt uses it for the nested build in <build>/fuzz-build; by hand:
#   cmake -C fuzz/clang-fuzz.cmake -S . -B build-fuzz && cmake --build build-fuzz
# Another clang: add -DCMAKE_CXX_COMPILER=clang++-NN.
set(CMAKE_CXX_COMPILER clang++ CACHE FILEPATH "C++ compiler (clang, with libFuzzer)")
set(VRL_FUZZ_ONLY ON CACHE BOOL "Build only vrl_util, vrl_render, vrl_proto, vrl_service_common, vrl_job and the fuzzers")
set(VRL_BUILD_TESTS OFF CACHE BOOL "Build the test suite")
# A build type of its own: -O1 -g with assertions on (no NDEBUG).
set(CMAKE_BUILD_TYPE Fuzz CACHE STRING "Build type")
set(CMAKE_CXX_FLAGS_FUZZ "-O1 -g" CACHE STRING "Flags of the Fuzz build type")
# Every object gets coverage instrumentation and the sanitizers; the fuzz
# executables add -fsanitize=fuzzer at link time (fuzz/CMakeLists.txt), other
# executables (the seed writer) link the sanitizer runtimes only.
set(CMAKE_CXX_FLAGS
    "-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer"
    CACHE STRING "C++ flags")
set(CMAKE_EXE_LINKER_FLAGS "-fsanitize=address,undefined" CACHE STRING "Linker flags for executables")
