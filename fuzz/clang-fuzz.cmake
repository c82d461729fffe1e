# Initial cache of the clang sanitizer build (cmake -C fuzz/clang-fuzz.cmake): the whole
# project, its tests and the libFuzzer targets (VRL_FUZZ), every object compiled with
# AddressSanitizer, UndefinedBehaviorSanitizer and libFuzzer's coverage
# (-fsanitize=fuzzer-no-link), so that the fuzzers link the very libraries the tests run.
# .ci/sanitizers builds build-sanitizers/ with it; by hand:
#   cmake -C fuzz/clang-fuzz.cmake -S . -B build-fuzz
#   cmake --build build-fuzz -j2 --target vrl_fuzzers    # the fuzzers alone; no target: everything
# Another clang: add -DCMAKE_CXX_COMPILER=clang++-NN.
set(CMAKE_CXX_COMPILER clang++ CACHE FILEPATH "C++ compiler (clang, with libFuzzer)")
set(VRL_FUZZ ON CACHE BOOL "Build the libFuzzer targets and the fuzz.* tests (clang only; fuzz/README.md)")
# A build type of its own: -O2 with line tables only (-g1: the function, file and line the
# sanitizers' stack traces print), assertions on (no NDEBUG). Not -O1: instrumented, the
# Highway kernel (render/vrl/vrl_kernel.cpp, the longest object, alone on the critical path)
# compiles 4x slower at -O1 (467 s of CPU against 113 s), more than the 10-15% that -O1
# saves on the other objects (renderer.cpp: 17-19 s against 19-21 s).
set(CMAKE_BUILD_TYPE Sanitize CACHE STRING "Build type")
set(CMAKE_CXX_FLAGS_SANITIZE "-O2 -g1" CACHE STRING "Flags of the Sanitize build type")
# Every object gets the sanitizers and the coverage instrumentation; any report is fatal
# (no recovery). The fuzz executables add -fsanitize=fuzzer (libFuzzer's main) at link
# time (fuzz/CMakeLists.txt); other executables link the sanitizer runtimes only.
set(CMAKE_CXX_FLAGS
    "-fsanitize=address,undefined,fuzzer-no-link -fno-sanitize-recover=all -fno-omit-frame-pointer"
    CACHE STRING "C++ flags")
set(CMAKE_EXE_LINKER_FLAGS "-fsanitize=address,undefined" CACHE STRING "Linker flags for executables")
