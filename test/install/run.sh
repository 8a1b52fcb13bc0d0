#!/usr/bin/env bash
# Installs a bvc3d build into a scratch prefix and builds a separate project against it, as a user
# would: find_package(bvc3d) + bvc3d::bvc3d, example/minimal.cpp, every public header on its own.
#   bash test/install/run.sh build        (ctest runs it as the test install_consumer)
set -euo pipefail
[ $# -eq 1 ] || { echo "usage: $0 BUILD_DIR" >&2; exit 2; }
build=$(cd "$1" && pwd)
source_dir=$(cd "$(dirname "$0")/../.." && pwd)
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
prefix="$scratch/prefix"

cmake --install "$build" --prefix "$prefix" >"$scratch/install.log"
echo "install: installed into a scratch prefix: $(find "$prefix" -type f | wc -l) files"

# Kernels and internals stay private (cmake/Install.cmake lists them and writes the list to the build).
while read -r header; do
  if [ -e "$prefix/include/$header" ]; then
    echo "install: private header installed: include/$header" >&2
    exit 1
  fi
done < "$build/private-headers.txt"
# The installed package must not point back into the source or build tree.
if grep -rl -e "$source_dir" -e "$build" "$prefix/lib/cmake/bvc3d"; then
  echo "install: the installed CMake package names the source or build tree (files above)" >&2
  exit 1
fi
for file in lib/libbvc3d.a bin/bvc3d lib/cmake/bvc3d/bvc3dConfig.cmake lib/cmake/bvc3d/bvc3dConfigVersion.cmake \
            lib/cmake/bvc3d/bvc3dTargets.cmake; do
  [ -e "$prefix/$file" ] || { echo "install: missing $file" >&2; exit 1; }
done

# The consumer project finds only the scratch prefix, never a package registry.
cmake -S "$source_dir/test/install/consumer" -B "$scratch/consumer" -G Ninja \
  -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF -DBVC3D_SOURCE_DIR="$source_dir" \
  >"$scratch/configure.log" || { cat "$scratch/configure.log" >&2; exit 1; }
grep "bvc3d .* from" "$scratch/configure.log"
cmake --build "$scratch/consumer" -j "$(nproc)" >"$scratch/build.log" \
  || { cat "$scratch/build.log" >&2; exit 1; }
echo "install: example/minimal.cpp and each installed header built against the installed package"

output=$("$scratch/consumer/minimal")
echo "$output"
grep -q "960 BVCs, max rate 0.5" <<<"$output" \
  || { echo "install: the consumer's minimal did not print '960 BVCs, max rate 0.5'" >&2; exit 1; }
"$prefix/bin/bvc3d" --version
echo "install: passed"
