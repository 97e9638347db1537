# `tessera view` (frontends/desktop/): a GLFW window with an OpenGL ES
# context through EGL and Dear ImGui controls. On by default when Debian's
# libglfw3-dev and libimgui-dev are installed; without them the command
# exists and says what to install (frontends/desktop/ViewUnavailable.cpp).
option(TESSERA_DESKTOP_VIEWER "Build the desktop viewer (tessera view) when GLFW and ImGui are found"
       ON)
set(TESSERA_DESKTOP_DIR ${CMAKE_SOURCE_DIR}/frontends/desktop)
# The subcommand's options are parsed whether or not the window can be built.
target_sources(tessera_cli PRIVATE ${TESSERA_DESKTOP_DIR}/ViewCommand.cpp)
set(TESSERA_DESKTOP_FOUND OFF)
if(TESSERA_DESKTOP_VIEWER)
  pkg_check_modules(GLFW3 IMPORTED_TARGET glfw3)
  # Debian's imgui.pc requires stb (ImGui's font rasteriser and rect packer).
  pkg_check_modules(IMGUI IMPORTED_TARGET imgui)
  if(GLFW3_FOUND AND IMGUI_FOUND)
    set(TESSERA_DESKTOP_FOUND ON)
  endif()
endif()

if(TESSERA_DESKTOP_FOUND)
  message(STATUS "tessera view: GLFW ${GLFW3_VERSION} + Dear ImGui ${IMGUI_VERSION}")
  # The gpu layer's GLFW window (include/tessera/gpu/GlfwWindow.h), apart
  # from tessera_gpu so that the layer never needs GLFW.
  add_library(tessera_gpu_glfw STATIC ${CMAKE_SOURCE_DIR}/src/gpu/GlfwWindow.cpp)
  target_compile_options(tessera_gpu_glfw PRIVATE ${TESSERA_WARNINGS})
  target_link_libraries(tessera_gpu_glfw PUBLIC tessera_gpu PRIVATE PkgConfig::GLFW3)

  # The panels drawn without a window (frontends/desktop/Panels.h), apart so
  # that tests/desktop draws and clicks them in an ImGui context of its own.
  file(GLOB TESSERA_DESKTOP_PANELS CONFIGURE_DEPENDS ${TESSERA_DESKTOP_DIR}/Panels*.cpp)
  add_library(tessera_desktop_panels STATIC ${TESSERA_DESKTOP_PANELS})
  target_compile_options(tessera_desktop_panels PRIVATE ${TESSERA_WARNINGS})
  # SYSTEM: ImGui's and GLFW's headers are not ours to keep free of warnings.
  target_include_directories(tessera_desktop_panels SYSTEM PUBLIC ${IMGUI_INCLUDE_DIRS})
  target_link_libraries(tessera_desktop_panels PUBLIC tessera PkgConfig::IMGUI)

  file(GLOB TESSERA_DESKTOP_SOURCES CONFIGURE_DEPENDS ${TESSERA_DESKTOP_DIR}/*.cpp)
  list(REMOVE_ITEM TESSERA_DESKTOP_SOURCES ${TESSERA_DESKTOP_DIR}/ViewCommand.cpp
       ${TESSERA_DESKTOP_DIR}/ViewUnavailable.cpp ${TESSERA_DESKTOP_PANELS})
  target_sources(tessera_cli PRIVATE ${TESSERA_DESKTOP_SOURCES})
  # SYSTEM, as above; GLFW's too.
  target_include_directories(tessera_cli SYSTEM PRIVATE ${IMGUI_INCLUDE_DIRS} ${GLFW3_INCLUDE_DIRS})
  target_link_libraries(tessera_cli PRIVATE tessera_desktop_panels tessera_gpu_glfw
                                            PkgConfig::GLFW3 PkgConfig::IMGUI ${CMAKE_DL_LIBS})
else()
  message(STATUS "tessera view: off (needs libglfw3-dev and libimgui-dev)")
  target_sources(tessera_cli PRIVATE ${TESSERA_DESKTOP_DIR}/ViewUnavailable.cpp)
endif()

# tests/desktop: the panels of frontends/desktop/Panels.h drawn in an ImGui
# context without a platform backend and clicked there, over sessions on the
# headless EGL context (called from the tests' block of CMakeLists.txt).
function(tessera_desktop_tests)
  if(NOT TESSERA_DESKTOP_FOUND)
    return()
  endif()
  file(GLOB tsrcs CONFIGURE_DEPENDS ${CMAKE_SOURCE_DIR}/tests/desktop/*.cpp)
  add_executable(test_desktop ${tsrcs})
  target_include_directories(test_desktop PRIVATE ${CMAKE_SOURCE_DIR}/frontends ${CMAKE_SOURCE_DIR}/src
                                                  ${CMAKE_SOURCE_DIR}/tests)
  target_compile_options(test_desktop PRIVATE ${TESSERA_WARNINGS})
  target_compile_definitions(test_desktop PRIVATE
    TESSERA_TEST_DATA_DIR="${CMAKE_SOURCE_DIR}/tests/data")
  target_link_libraries(test_desktop PRIVATE tessera_desktop_panels tessera GTest::gtest
                        GTest::gtest_main nlohmann_json::nlohmann_json ZLIB::ZLIB)
  tessera_precompile(test_desktop <gtest/gtest.h>)
  gtest_discover_tests(test_desktop DISCOVERY_TIMEOUT 60 PROPERTIES TIMEOUT 600)

  # tests/glfw: a real X drag-and-drop onto a GlfwWindow (the test is the
  # XDND source), under xvfb-run where it is installed; skipped without a display.
  pkg_check_modules(X11 IMPORTED_TARGET x11)
  if(NOT X11_FOUND)
    return()
  endif()
  add_executable(test_glfw_window ${CMAKE_SOURCE_DIR}/tests/glfw/GlfwDropTest.cpp)
  target_compile_options(test_glfw_window PRIVATE ${TESSERA_WARNINGS})
  target_include_directories(test_glfw_window SYSTEM PRIVATE ${GLFW3_INCLUDE_DIRS})
  target_link_libraries(test_glfw_window PRIVATE tessera_gpu_glfw PkgConfig::GLFW3 PkgConfig::X11
                        GTest::gtest GTest::gtest_main)
  # Listed and run through xvfb-run (an X server of its own per run).
  find_program(TESSERA_XVFB_RUN xvfb-run)
  if(TESSERA_XVFB_RUN)
    set_target_properties(test_glfw_window PROPERTIES CROSSCOMPILING_EMULATOR
                          "${TESSERA_XVFB_RUN};-a;-s;-screen 0 640x480x24")
  endif()
  gtest_discover_tests(test_glfw_window DISCOVERY_TIMEOUT 60 PROPERTIES TIMEOUT 120 RESOURCE_LOCK xvfb)
endfunction()
