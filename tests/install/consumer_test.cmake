# The installed package as a user meets it (ctest Install.*): `cmake --install` of BUILD_DIR into
# a fresh prefix under WORK_DIR, then
# 1. the shared libraries carry a SONAME and the programs, the headers and the spec are in place;
# 2. no installed header includes OpenEXR, Imath, OpenImageIO, OpenGL, Assimp or Embree, and the exported targets
#    name none of them;
# 3. the consumer project (consumer/) builds with find_package(conus) and runs; so does the installed
#    GL example (examples/reflection_gl) with the installed GLSL;
# 4. the same program builds with pkg-config's flags alone and runs.
# 5. with PYTHON, the installed Python package imports and works.
# Usage: cmake -DBUILD_DIR=... -DSOURCE_DIR=... -DWORK_DIR=... -DLIBDIR=lib [-DPYTHON=python3] -P consumer_test.cmake
cmake_minimum_required(VERSION 3.25)
foreach(var BUILD_DIR SOURCE_DIR WORK_DIR LIBDIR)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "consumer_test: ${var} is not set")
  endif()
endforeach()

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "consumer_test: `${ARGN}` failed (${rc}):\n${out}\n${err}")
  endif()
  set(run_output "${out}" PARENT_SCOPE)
endfunction()

set(prefix ${WORK_DIR}/prefix)
file(REMOVE_RECURSE ${WORK_DIR})
run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})

# 1. What is installed.
set(libdir ${prefix}/${LIBDIR})
foreach(path bin/conus ${LIBDIR}/cmake/conus/conusConfig.cmake ${LIBDIR}/cmake/conus/conusConfigVersion.cmake
        ${LIBDIR}/pkgconfig/conus.pc include/conus/codec/image/encode.h share/doc/conus/spec/conus-format.md
        share/man/man1/conus.1 ${LIBDIR}/python3/dist-packages/conus/__init__.py
        ${LIBDIR}/libconus_imageio_oiio.so ${LIBDIR}/conus/libconus_faces.so ${LIBDIR}/conus/libconus_http.so
        include/conus/codec/depth/glsl_interface.h share/conus/glsl/equation1.inc.glsl share/conus/glsl/intersect.inc.glsl
        share/conus/glsl/reflection.frag.glsl share/doc/conus/examples/reflection_gl/main.cpp)
  if(NOT EXISTS ${prefix}/${path})
    message(FATAL_ERROR "consumer_test: ${path} is not installed")
  endif()
endforeach()
foreach(lib core format imageio sceneio codec renderers)
  run(objdump -p ${libdir}/libconus_${lib}.so)
  if(NOT run_output MATCHES "SONAME +libconus_${lib}\\.so\\.1\n")
    message(FATAL_ERROR "consumer_test: libconus_${lib}.so has no SONAME libconus_${lib}.so.1")
  endif()
endforeach()
run(${prefix}/bin/conus --version)
# The modules loaded on first use (core/plugin.h) are found where they were installed: the demo
# reads nothing but writes PNG pictures through OpenImageIO's module.
run(${prefix}/bin/conus demo --size 256 --out ${WORK_DIR}/demo -q)
if(NOT EXISTS ${WORK_DIR}/demo/view-frame.png)
  message(FATAL_ERROR "consumer_test: the installed conus wrote no pictures: ${run_output}")
endif()
if(PYTHON)
  # The installed Python package finds the installed libraries (its RPATH), from any folder.
  set(ENV{PYTHONPATH} ${libdir}/python3/dist-packages)
  # (No semicolons: CMake would split the argument there.)
  run(${PYTHON} -c "import conus, numpy\nf = conus.encode(numpy.ones((8, 8, 3), 'float32'), size=(4, 4))\nprint(conus.__file__, f)")
  if(NOT run_output MATCHES "^${libdir}/python3/dist-packages/conus/__init__.py <conus.File 4x4")
    message(FATAL_ERROR "consumer_test: the installed package is not the one imported: ${run_output}")
  endif()
  unset(ENV{PYTHONPATH})
endif()

# 2. Nothing of OpenEXR, OpenImageIO or OpenGL leaks through the headers or the targets.
file(GLOB_RECURSE headers RELATIVE ${prefix}/include ${prefix}/include/conus/*.h)
foreach(header IN LISTS headers)
  file(STRINGS ${prefix}/include/${header} bad REGEX "^#[ \t]*include[ \t]*[<\"](Imf|Imath|OpenEXR|openexr|OpenImageIO|glad|EGL|GL/|GLES|osmesa|assimp|embree)")
  if(bad)
    message(FATAL_ERROR "consumer_test: ${header} includes a dependency's header: ${bad}")
  endif()
endforeach()
# What a consumer compiles and links against (the INTERFACE_ properties; the private shared
# libraries appear only in IMPORTED_LINK_DEPENDENT_LIBRARIES, CMake's note for the runtime linker).
file(GLOB targets_files ${libdir}/cmake/conus/conusTargets*.cmake)
foreach(f IN LISTS targets_files)
  file(STRINGS ${f} lines REGEX "INTERFACE_")
  foreach(line IN LISTS lines)
    if(line MATCHES "OpenEXR|OpenImageIO|OpenGL|OSMESA|Imath|EGL|assimp|embree")
      message(FATAL_ERROR "consumer_test: ${f} gives consumers a private dependency: ${line}")
    endif()
  endforeach()
endforeach()

# 3. find_package(conus).
set(build ${WORK_DIR}/consumer-build)
file(MAKE_DIRECTORY ${build})
run(${CMAKE_COMMAND} -S ${SOURCE_DIR}/tests/install/consumer -B ${build} -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_BUILD_TYPE=Release
    -DCHECK_EVERY_HEADER=ON)
run(${CMAKE_COMMAND} --build ${build})
run(${build}/consumer ${WORK_DIR}/cmake.exr)
message(STATUS "find_package consumer:\n${run_output}")

# 3b. The GL example of docs/reflections-in-your-renderer.md, as installed, built against the
# package (conus_GLSL_DIR, the installed GLSL) and run on an asset the installed conus bakes.
set(gl_build ${WORK_DIR}/reflection-gl-build)
run(${CMAKE_COMMAND} -S ${prefix}/share/doc/conus/examples/reflection_gl -B ${gl_build} -DCMAKE_PREFIX_PATH=${prefix}
    -DCMAKE_BUILD_TYPE=Release)
run(${CMAKE_COMMAND} --build ${gl_build})
file(WRITE ${WORK_DIR}/room.obj "v -3 -1 -3\nv 3 -1 -3\nv 3 -1 3\nv -3 -1 3\nv 0.4 -1 1.5\nv 1 -1 1.5\nv 1 0.5 1.5\nv 0.4 0.5 1.5\nf 1 4 3 2\nf 5 6 7 8\n")
run(${prefix}/bin/conus bake reflection ${WORK_DIR}/room.obj --center 0,0,0 --size 32 -o ${WORK_DIR}/asset.exr -q)
run(${gl_build}/reflection_gl ${WORK_DIR}/asset.exr -0.8,0.5,3,0,0,0,30 64x48 sphere 0.5 0,0,1 ${WORK_DIR}/mirror.exr)
if(NOT EXISTS ${WORK_DIR}/mirror.exr)
  message(FATAL_ERROR "consumer_test: the reflection example wrote no frame: ${run_output}")
endif()
message(STATUS "reflection example:\n${run_output}")

# 4. pkg-config.
set(ENV{PKG_CONFIG_PATH} ${libdir}/pkgconfig)
run(pkg-config --cflags --libs conus)
string(STRIP "${run_output}" flags)
separate_arguments(flags UNIX_COMMAND "${flags}")
run(c++ ${SOURCE_DIR}/tests/install/consumer/main.cpp ${flags} -Wl,-rpath,${libdir} -o ${WORK_DIR}/consumer-pc)
run(${WORK_DIR}/consumer-pc ${WORK_DIR}/pc.exr)
message(STATUS "pkg-config consumer:\n${run_output}")
