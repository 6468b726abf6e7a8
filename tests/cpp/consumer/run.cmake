# ctest driver (cmake -P): install the core built in BUILD_DIR into a fresh prefix under WORK,
# configure and build the consumer project against that prefix alone, and run it.
#   -DBUILD_DIR= -DSOURCE_DIR= -DWORK= -DGENERATOR= -DMAKE_PROGRAM= -DCXX= -DVERSION=
foreach(v BUILD_DIR SOURCE_DIR WORK GENERATOR CXX VERSION)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "run.cmake needs -D${v}=...")
  endif()
endforeach()
file(REMOVE_RECURSE "${WORK}")
set(prefix "${WORK}/prefix")

function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  message(STATUS "${what}:\n${out}${err}")
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${what} failed (${rc})")
  endif()
endfunction()

run("install into ${prefix}" "${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${prefix}")
foreach(f include/hovering/hovering.hpp include/hovering/version.hpp)
  if(NOT EXISTS "${prefix}/${f}")
    message(FATAL_ERROR "the install has no ${f}")
  endif()
endforeach()
file(GLOB_RECURSE private_headers "${prefix}/include/hovering/detail/*")
if(private_headers)
  message(FATAL_ERROR "the install holds private headers: ${private_headers}")
endif()
set(make_program)
if(MAKE_PROGRAM)
  set(make_program "-DCMAKE_MAKE_PROGRAM=${MAKE_PROGRAM}")
endif()
# Only the prefix: the consumer cannot reach the source tree or the build directory.
run("configure the consumer" "${CMAKE_COMMAND}" -S "${SOURCE_DIR}" -B "${WORK}/build" -G "${GENERATOR}"
    ${make_program} "-DCMAKE_CXX_COMPILER=${CXX}" -DCMAKE_BUILD_TYPE=Release "-DCMAKE_PREFIX_PATH=${prefix}"
    "-DEXPECTED_VERSION=${VERSION}" -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF)
run("build the consumer" "${CMAKE_COMMAND}" --build "${WORK}/build")
run("run the consumer" "${WORK}/build/consumer")
