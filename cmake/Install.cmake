# Installation and the CMake package (included at the end of the top
# CMakeLists.txt, when every layer is defined). `cmake --install build
# --prefix P` gives P/include/tessera/**, P/lib/libtessera_<layer>.a (the GLSL
# is compiled into tessera_gpu), P/bin/tessera and
# P/lib/cmake/Tessera/{TesseraConfig,TesseraConfigVersion,TesseraTargets}.cmake,
# so that find_package(Tessera) gives tessera::tessera and tessera::<layer>.
# examples/embed builds against it (scripts/embed-test.sh).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

# Every layer tessera_layer() made, in definition order: a layer links only
# layers defined before it, so the reverse is a dependency order (each before
# the layers it needs), which is how the umbrella target lists them.
get_property(TESSERA_LAYERS GLOBAL PROPERTY TESSERA_LAYERS)
set(TESSERA_LAYERS_TOP_DOWN ${TESSERA_LAYERS})
list(REVERSE TESSERA_LAYERS_TOP_DOWN)
target_link_libraries(tessera INTERFACE ${TESSERA_LAYERS_TOP_DOWN})
# The public headers use C++20 (std::span, designated initialisers).
target_compile_features(tessera INTERFACE cxx_std_20)

foreach(layer IN LISTS TESSERA_LAYERS)
  string(REGEX REPLACE "^tessera_" "" short ${layer})
  set_target_properties(${layer} PROPERTIES EXPORT_NAME ${short})
endforeach()
set_target_properties(tessera PROPERTIES EXPORT_NAME tessera)

install(TARGETS ${TESSERA_LAYERS} tessera EXPORT TesseraTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(TARGETS tessera_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY ${CMAKE_SOURCE_DIR}/include/tessera DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})

set(TESSERA_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/Tessera)
install(EXPORT TesseraTargets NAMESPACE tessera:: DESTINATION ${TESSERA_CMAKE_DIR})
configure_package_config_file(${CMAKE_SOURCE_DIR}/cmake/TesseraConfig.cmake.in
                              ${CMAKE_BINARY_DIR}/TesseraConfig.cmake
                              INSTALL_DESTINATION ${TESSERA_CMAKE_DIR})
# 0.x: a minor version may change the API, so only the same minor matches.
write_basic_package_version_file(${CMAKE_BINARY_DIR}/TesseraConfigVersion.cmake
                                 VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_BINARY_DIR}/TesseraConfig.cmake ${CMAKE_BINARY_DIR}/TesseraConfigVersion.cmake
        DESTINATION ${TESSERA_CMAKE_DIR})
