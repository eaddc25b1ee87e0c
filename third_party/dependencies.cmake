# Every dependency is a Debian package installed by scripts/setup (see README.md).
# Nothing is downloaded at build time.

find_package(glm REQUIRED)                    # libglm-dev: vector maths, header only
find_package(tomlplusplus 3 REQUIRED)         # libtomlplusplus-dev: scene files
find_package(nlohmann_json 3 REQUIRED)        # nlohmann-json3-dev: --json output
find_package(OpenMP REQUIRED COMPONENTS CXX)  # libgomp (with g++): the fast solver's threads
find_package(Eigen3 3.3 REQUIRED NO_MODULE)  # libeigen3-dev: sparse Cholesky of the projective solver
find_package(tinyobjloader REQUIRED)          # libtinyobjloader-dev (2.0.0~rc10, versioned "2rc10": no version asked): OBJ meshes of mesh colliders

if(CLOTHSIM_BUILD_APP)
  find_package(CLI11 2 REQUIRED)              # libcli11-dev: command-line parsing
  find_package(glfw3 3.3 REQUIRED)            # libglfw3-dev: window and input
  set(OpenGL_GL_PREFERENCE GLVND)
  find_package(OpenGL REQUIRED COMPONENTS OpenGL)
  find_package(PkgConfig REQUIRED)
  pkg_check_modules(IMGUI REQUIRED IMPORTED_TARGET imgui)   # libimgui-dev (with GLFW/OpenGL3 backends)
  pkg_check_modules(STB REQUIRED IMPORTED_TARGET stb)       # libstb-dev (implementations included)
  include(glad)
endif()

if(CLOTHSIM_BUILD_TESTS)
  find_package(Catch2 2 REQUIRED)             # catch2 (v2): unit tests
  include(Catch)
endif()
