# Sourced by setup.sh and test.sh (not run): compile through ccache when it is installed. Nothing
# needs it (CI and a fresh machine build without it); a developer's machine with it (Debian:
# apt-get install ccache) recompiles nothing it has compiled before: a new build tree, a checkout
# switched back and forth, the C++ tests' tree after the set-up's. CMake reads the variable below
# when it configures a build tree for the first time. CMAKE_CXX_COMPILER_LAUNCHER= (set, empty)
# builds without ccache; a launcher already set is kept.
if [ -z "${CMAKE_CXX_COMPILER_LAUNCHER+x}" ] && command -v ccache >/dev/null 2>&1; then
  export CMAKE_CXX_COMPILER_LAUNCHER=ccache
  # Paths inside the checkout are hashed relative to the build tree, so the set-up's tree
  # (build/<wheel tag>) and the C++ tests' (build/ctest), at the same depth, share the core's
  # objects: the C++ tests' build then compiles only the tests and the sweep executable.
  export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$PWD}"
  # ccache hashes the compiler's name too, and left to themselves the two configurations name the
  # same GCC differently (scikit-build-core's /usr/bin/g++, a plain cmake /usr/bin/c++): one name.
  export CXX="${CXX:-c++}"
fi
