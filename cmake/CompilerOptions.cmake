# Warning and code-generation flags for bvc3d's own targets (not its dependencies).
add_library(bvc3d_options INTERFACE)
target_compile_options(bvc3d_options INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor
  # Same seed => bit-identical results: forbid the compiler from fusing multiply-adds on its own.
  -ffp-contract=off)

if(BVC3D_SANITIZE)
  target_compile_options(bvc3d_options INTERFACE -fsanitize=address,undefined -fno-omit-frame-pointer
                                                 -fno-sanitize-recover=undefined)
  target_link_options(bvc3d_options INTERFACE -fsanitize=address,undefined)
endif()

# Fuzzing (scripts/fuzz): coverage for libFuzzer and both sanitizers in every object of the library;
# the fuzz targets themselves link libFuzzer's main.
if(BVC3D_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "BVC3D_FUZZ needs clang (CC=clang CXX=clang++)")
  endif()
  target_compile_options(bvc3d_options INTERFACE -fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer
                                                 -fno-sanitize-recover=undefined -O1 -gline-tables-only)
  target_link_options(bvc3d_options INTERFACE -fsanitize=address,undefined)
endif()
