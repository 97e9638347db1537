# The browser build of the viewer (included from CMakeLists.txt under
# emcmake; scripts/web.sh runs it). Compiles the layers the viewer needs —
# core, gpu, lod, reference, lattice, layout, render, viewer and io's readers — with Debian's
# emscripten into the site's tessera-core.js + tessera-core.wasm, an ES
# module factory (-sMODULARIZE -sEXPORT_ES6: every instance has its own
# memory and WebGL context) that frontends/web/tessera.js wraps for pages. nifticlib, zlib,
# DCMTK and libpng are not available to emscripten here. The io readers
# need none of them to read (they parse every header themselves, on byte
# sources): files picked or dropped in the page are read by the same
# readers as the CLI's, their gzip/zlib inflated by the page's pako
# (frontends/web/src/InflaterPako.cpp replaces io/InflaterZlib.cpp; frontends/web/package.json
# pins pako). The writers (zlib, nifticlib) stay native; DICOM is read by
# io/DicomBasicReader.cpp instead of DCMTK (frontends/web/src/DicomBasicSeries.cpp
# routes the path entry points to it), and PNG I/O reports that it is not
# built in (frontends/web/src/PngUnavailable.cpp). The gpu layer's EGL platform
# (GlContext.cpp) is replaced by the browser's (src/gpu/GlContextWebGL.cpp,
# which makes the WebGL context on the page's canvas; the native build
# compiles it empty).
# No pthreads: SharedArrayBuffer needs cross-origin isolation a static page
# cannot count on; code that sizes thread pools sees one core.
cmake_minimum_required(VERSION 3.25)

# Header-only libraries from the host (glm, nlohmann_json) without the rest
# of /usr/include, which must not shadow emscripten's sysroot.
find_path(TESSERA_HOST_GLM glm/glm.hpp PATHS /usr/include NO_CMAKE_FIND_ROOT_PATH REQUIRED)
find_path(TESSERA_HOST_JSON nlohmann/json.hpp PATHS /usr/include NO_CMAKE_FIND_ROOT_PATH REQUIRED)
find_path(TESSERA_HOST_PNG png.h PATHS /usr/include/libpng16 NO_CMAKE_FIND_ROOT_PATH REQUIRED)
set(TESSERA_HOST_INC ${CMAKE_BINARY_DIR}/hostinc)
file(MAKE_DIRECTORY ${TESSERA_HOST_INC})
foreach(pair "glm;${TESSERA_HOST_GLM}/glm" "nlohmann;${TESSERA_HOST_JSON}/nlohmann"
        "png.h;${TESSERA_HOST_PNG}/png.h" "pngconf.h;${TESSERA_HOST_PNG}/pngconf.h"
        "pnglibconf.h;${TESSERA_HOST_PNG}/pnglibconf.h")
  list(GET pair 0 name)
  list(GET pair 1 target)
  if(NOT EXISTS ${TESSERA_HOST_INC}/${name})
    file(CREATE_LINK ${target} ${TESSERA_HOST_INC}/${name} SYMBOLIC)
  endif()
endforeach()

include(${CMAKE_SOURCE_DIR}/cmake/EmbeddedShaders.cmake)

# From io: the readers and procedural sources; not the writers, DICOM, nor
# the zlib inflater.
file(GLOB TESSERA_WEB_IO CONFIGURE_DEPENDS ${CMAKE_SOURCE_DIR}/src/io/*.cpp)
# OME-Zarr: the store reader is shared; its storage is the page's fetch()
# (frontends/web/src/ZarrFetchStorage.cpp) instead of folders and libcurl (Http*,
# ZarrVolume), and its codecs frontends/web/src/ZarrCodecsWeb.cpp (pako) instead of
# Debian's zlib, libzstd and libblosc (ZarrCodecs), which emscripten cannot
# link here. DICOM: the reader without DCMTK (DicomBasicReader,
# DicomSeries), not DCMTK's (DicomSeriesReader, DicomToolkit, DicomNesting).
list(FILTER TESSERA_WEB_IO EXCLUDE REGEX
     "/(.*Writer|DicomSeriesReader|DicomToolkit|DicomNesting|InflaterZlib|OutputFile|ZarrVolume|ZarrCodecs|Http.*|DicomWeb.*|Jpeg2000Frame|Htj2kFrame)\\.cpp$")
set(TESSERA_WEB_SOURCES ${TESSERA_GLSL_CPP} ${TESSERA_WEB_IO})
foreach(layer core gpu lod reference lattice layout render viewer session)
  file(GLOB_RECURSE srcs CONFIGURE_DEPENDS ${CMAKE_SOURCE_DIR}/src/${layer}/*.cpp)
  list(APPEND TESSERA_WEB_SOURCES ${srcs})
endforeach()
# The session, its settings, view, exploration, run and refinement loop;
# not its headless device (EGL) nor its opening of named files and stores
# (the page hands volumes over in memory and fetches stores itself).
list(REMOVE_ITEM TESSERA_WEB_SOURCES ${CMAKE_SOURCE_DIR}/src/session/SessionOpen.cpp
     ${CMAKE_SOURCE_DIR}/src/session/Convert.cpp
     ${CMAKE_SOURCE_DIR}/src/session/VolumePyramid.cpp)
# The EGL platform; src/gpu/GlContextWebGL.cpp is the browser's.
list(REMOVE_ITEM TESSERA_WEB_SOURCES ${CMAKE_SOURCE_DIR}/src/gpu/GlContext.cpp)
file(GLOB TESSERA_WEB_FRONT CONFIGURE_DEPENDS ${CMAKE_SOURCE_DIR}/frontends/web/src/*.cpp)

set_source_files_properties(${CMAKE_SOURCE_DIR}/src/core/TransferFunction.cpp PROPERTIES
  COMPILE_OPTIONS "-include;${CMAKE_SOURCE_DIR}/frontends/web/src/compat/FloatToChars.h")
# The io readers parse numbers with std::from_chars, which this libc++ lacks
# for floating point.
set_source_files_properties(${TESSERA_WEB_IO} PROPERTIES
  COMPILE_OPTIONS "-include;${CMAKE_SOURCE_DIR}/frontends/web/src/compat/FloatFromChars.h")

set(TESSERA_WEB_SITE ${CMAKE_BINARY_DIR}/site)
add_executable(tessera_web ${TESSERA_WEB_SOURCES} ${TESSERA_WEB_FRONT})
set_target_properties(tessera_web PROPERTIES OUTPUT_NAME tessera-core SUFFIX ".js"
                                             RUNTIME_OUTPUT_DIRECTORY ${TESSERA_WEB_SITE})
target_include_directories(tessera_web PRIVATE ${CMAKE_SOURCE_DIR}/include ${CMAKE_SOURCE_DIR}/src)
target_include_directories(tessera_web SYSTEM PRIVATE ${TESSERA_HOST_INC})
target_compile_definitions(tessera_web PRIVATE GLM_FORCE_CXX17)
# -fexceptions: every user-facing error is a C++ exception that must reach
# the page as a message instead of aborting the module.
set(TESSERA_WEB_FLAGS -O2 -fexceptions)
target_compile_options(tessera_web PRIVATE ${TESSERA_WEB_FLAGS} -Wall -Wextra)
target_link_options(tessera_web PRIVATE ${TESSERA_WEB_FLAGS}
  -sMIN_WEBGL_VERSION=1 -sMAX_WEBGL_VERSION=2 -sALLOW_MEMORY_GROWTH=1 -sINITIAL_MEMORY=64MB
  --js-library ${CMAKE_SOURCE_DIR}/frontends/web/src/InflaterPako.js
  -sMODULARIZE=1 -sEXPORT_ES6=1 -sEXPORT_NAME=createTesseraModule -sENVIRONMENT=web
  "-sEXPORTED_FUNCTIONS=_malloc,_free"
  "-sEXPORTED_RUNTIME_METHODS=ccall,cwrap,UTF8ToString,HEAPU8,HEAPF32")

set_property(TARGET tessera_web APPEND PROPERTY LINK_DEPENDS
             ${CMAKE_SOURCE_DIR}/frontends/web/src/InflaterPako.js)

# The static page next to the module, and pako from frontends/web/node_modules
# (`npm ci` in frontends/web/, which scripts/web.sh and scripts/setup.sh run).
set(TESSERA_PAKO ${CMAKE_SOURCE_DIR}/frontends/web/node_modules/pako/dist/pako_inflate.min.js)
if(NOT EXISTS ${TESSERA_PAKO})
  message(FATAL_ERROR "${TESSERA_PAKO} is missing: run `npm ci` in frontends/web/ (scripts/web.sh does)")
endif()
# numcodecs' blosc and zstd decoders (WebAssembly builds of c-blosc and
# zstd; MIT), which the page loads for stores with those compressors
# (frontends/web/zarr-url.js), into the site's numcodecs/.
set(TESSERA_NUMCODECS ${CMAKE_SOURCE_DIR}/frontends/web/node_modules/numcodecs/dist)
if(NOT EXISTS ${TESSERA_NUMCODECS}/blosc.js)
  message(FATAL_ERROR "${TESSERA_NUMCODECS} is missing: run `npm ci` in frontends/web/ (scripts/web.sh does)")
endif()
file(GLOB TESSERA_NUMCODECS_JS ${TESSERA_NUMCODECS}/blosc.js ${TESSERA_NUMCODECS}/zstd.js
     ${TESSERA_NUMCODECS}/chunk-*.js)
foreach(f ${TESSERA_NUMCODECS_JS})
  get_filename_component(n ${f} NAME)
  configure_file(${f} ${TESSERA_WEB_SITE}/numcodecs/${n} COPYONLY)
endforeach()
configure_file(${CMAKE_SOURCE_DIR}/frontends/web/node_modules/numcodecs/LICENSE
               ${TESSERA_WEB_SITE}/numcodecs/LICENSE COPYONLY)
# The compressed-DICOM decoders (frontends/web/dicom-codecs.js loads each
# only when a frame needs it): WebAssembly builds of libjpeg-turbo, CharLS,
# OpenJPEG and OpenJPH, and jpeg-lossless-decoder-js, into the site's codecs/.
set(TESSERA_NPM ${CMAKE_SOURCE_DIR}/frontends/web/node_modules)
set(TESSERA_CODEC_FILES
  @cornerstonejs/codec-libjpeg-turbo-8bit/dist/libjpegturbowasm_decode.js
  @cornerstonejs/codec-libjpeg-turbo-8bit/dist/libjpegturbowasm_decode.wasm
  @cornerstonejs/codec-charls/dist/charlswasm_decode.js
  @cornerstonejs/codec-charls/dist/charlswasm_decode.wasm
  @cornerstonejs/codec-openjpeg/dist/openjpegwasm_decode.js
  @cornerstonejs/codec-openjpeg/dist/openjpegwasm_decode.wasm
  @cornerstonejs/codec-openjph/dist/openjphjs.js
  @cornerstonejs/codec-openjph/dist/openjphjs.wasm
  jpeg-lossless-decoder-js/release/lossless-min.js)
foreach(f ${TESSERA_CODEC_FILES})
  if(NOT EXISTS ${TESSERA_NPM}/${f})
    message(FATAL_ERROR "${TESSERA_NPM}/${f} is missing: run `npm ci` in frontends/web/ (scripts/web.sh does)")
  endif()
  get_filename_component(n ${f} NAME)
  configure_file(${TESSERA_NPM}/${f} ${TESSERA_WEB_SITE}/codecs/${n} COPYONLY)
endforeach()
foreach(p codec-libjpeg-turbo-8bit codec-charls codec-openjpeg codec-openjph)
  if(EXISTS ${TESSERA_NPM}/@cornerstonejs/${p}/LICENSE)
    configure_file(${TESSERA_NPM}/@cornerstonejs/${p}/LICENSE ${TESSERA_WEB_SITE}/codecs/LICENSE-${p} COPYONLY)
  endif()
endforeach()
configure_file(${TESSERA_NPM}/jpeg-lossless-decoder-js/LICENSE
               ${TESSERA_WEB_SITE}/codecs/LICENSE-jpeg-lossless-decoder-js COPYONLY)
# 12-bit JPEG extended: the JavaScript decoder of cornerstone's image loader
# (only this one file of the package), as codecs/jpeg12.js.
set(TESSERA_JPEG12 ${TESSERA_NPM}/@cornerstonejs/dicom-image-loader/dist/esm/codecs/jpeg.js)
if(NOT EXISTS ${TESSERA_JPEG12})
  message(FATAL_ERROR "${TESSERA_JPEG12} is missing: run `npm ci` in frontends/web/ (scripts/web.sh does)")
endif()
# Its output stage (quantizeAndInverse) scales 8-bit's level shift and range
# by 4095/255 instead of 16, which adds 15-16 to every 12-bit sample (against
# dcmdjpeg: every pixel of pydicom's JPGExtended.dcm 14-15 too high). The
# three constants are rewritten for any precision P (M = 2^P - 1): level
# shift (M + 1) * 8 + 8 and upper limit 8 * M - 16, which are 2056 and 2024
# at P = 8, as before. The copy fails the build if the pinned text changes.
file(READ ${TESSERA_JPEG12} jpeg12)
set(jpeg12_fixes
  "2056 / component.bitConversion" "((Math.round(255 / component.bitConversion) + 1) * 8 + 8)" 2
  "2024 / component.bitConversion" "(Math.round(255 / component.bitConversion) * 8 - 16)" 1
  "? 255 / component.bitConversion" "? Math.round(255 / component.bitConversion)" 1)
while(jpeg12_fixes)
  list(POP_FRONT jpeg12_fixes from to times)
  string(REPLACE "${from}" "" without "${jpeg12}")
  string(LENGTH "${jpeg12}" all)
  string(LENGTH "${without}" rest)
  string(LENGTH "${from}" one)
  math(EXPR n "(${all} - ${rest}) / ${one}")
  if(NOT n EQUAL times)
    message(FATAL_ERROR "${TESSERA_JPEG12}: expected '${from}' ${times} time(s), found ${n}: the pinned decoder changed")
  endif()
  string(REPLACE "${from}" "${to}" jpeg12 "${jpeg12}")
endwhile()
file(WRITE ${TESSERA_WEB_SITE}/codecs/jpeg12.js.new "${jpeg12}")
configure_file(${TESSERA_WEB_SITE}/codecs/jpeg12.js.new ${TESSERA_WEB_SITE}/codecs/jpeg12.js COPYONLY)
file(REMOVE ${TESSERA_WEB_SITE}/codecs/jpeg12.js.new)
set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${TESSERA_JPEG12})
configure_file(${TESSERA_NPM}/@cornerstonejs/dicom-image-loader/LICENSE
               ${TESSERA_WEB_SITE}/codecs/LICENSE-dicom-image-loader COPYONLY)
file(GLOB TESSERA_WEB_STATIC CONFIGURE_DEPENDS ${CMAKE_SOURCE_DIR}/frontends/web/*.html
     ${CMAKE_SOURCE_DIR}/frontends/web/*.js ${CMAKE_SOURCE_DIR}/frontends/web/*.css)
foreach(f ${TESSERA_WEB_STATIC} ${TESSERA_PAKO})
  get_filename_component(n ${f} NAME)
  configure_file(${f} ${TESSERA_WEB_SITE}/${n} COPYONLY)
endforeach()
# The embedding example (examples/embed-web), served from the site so that
# its import of ../../tessera.js finds the module.
file(GLOB TESSERA_EMBED_EXAMPLE CONFIGURE_DEPENDS ${CMAKE_SOURCE_DIR}/examples/embed-web/*)
foreach(f ${TESSERA_EMBED_EXAMPLE})
  get_filename_component(n ${f} NAME)
  configure_file(${f} ${TESSERA_WEB_SITE}/examples/embed-web/${n} COPYONLY)
endforeach()
