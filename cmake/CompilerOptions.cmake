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
