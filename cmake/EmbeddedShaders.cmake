# GLSL sources live next to the C++ that owns them; they are embedded into the
# library at build time (cmake/EmbedGlsl.cmake writes one C++ file) and looked
# up by file name (see gpu/ShaderSource.h). Included by the native build and
# the web build (cmake/Web.cmake); sets TESSERA_GLSL_CPP.
file(GLOB_RECURSE TESSERA_GLSL CONFIGURE_DEPENDS ${CMAKE_SOURCE_DIR}/src/*.glsl)
string(REPLACE ";" "|" TESSERA_GLSL_ARG "${TESSERA_GLSL}")
set(TESSERA_GLSL_CPP ${CMAKE_BINARY_DIR}/generated/EmbeddedShaders.cpp)
add_custom_command(
  OUTPUT ${TESSERA_GLSL_CPP}
  COMMAND ${CMAKE_COMMAND} -DOUT=${TESSERA_GLSL_CPP} -DROOT=${CMAKE_SOURCE_DIR}/src
          "-DFILES=${TESSERA_GLSL_ARG}" -P ${CMAKE_SOURCE_DIR}/cmake/EmbedGlsl.cmake
  DEPENDS ${TESSERA_GLSL} ${CMAKE_SOURCE_DIR}/cmake/EmbedGlsl.cmake
  COMMENT "Embedding GLSL shaders" VERBATIM)
