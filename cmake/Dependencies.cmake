# Every dependency comes from Debian's packages (see scripts/setup); nothing is vendored.
find_package(embree 3 REQUIRED)
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(assimp REQUIRED)
find_package(yaml-cpp REQUIRED)
find_package(HDF5 REQUIRED COMPONENTS C)
find_package(CLI11 REQUIRED)
# Gazebo (SDF) worlds: Debian's libsdformat-dev (SDFormat 12, the reference parser).
find_package(sdformat12 REQUIRED)
# SDFormat falls back to urdfdom on a file it cannot read, which logs through console_bridge: kept
# quiet while bvc3d parses (its own message says what is wrong). Debian's libconsole-bridge-dev.
find_package(console_bridge REQUIRED)
find_package(Threads REQUIRED)

if(BVC3D_WITH_MPI)
  find_package(MPI COMPONENTS C)
endif()
set(BVC3D_HAVE_MPI OFF)
if(MPI_C_FOUND)
  set(BVC3D_HAVE_MPI ON)
endif()

if(BVC3D_BUILD_PYTHON)
  # Debian's interpreter owns numpy/matplotlib/h5py; a different python3 may come first on PATH.
  if(NOT DEFINED Python_EXECUTABLE AND EXISTS /usr/bin/python3)
    set(Python_EXECUTABLE /usr/bin/python3)
  endif()
  set(PYBIND11_FINDPYTHON ON)
  find_package(Python 3.9 REQUIRED COMPONENTS Interpreter Development.Module)
  find_package(pybind11 2.6 REQUIRED CONFIG)
endif()
