# `tessera view` (src/app/ViewCommand.cpp): a GLFW window with an OpenGL ES
# context through EGL and Dear ImGui controls. On by default when Debian's
# libglfw3-dev and libimgui-dev are installed; without them the command
# exists and says what to install.
option(TESSERA_DESKTOP_VIEWER "Build the desktop viewer (tessera view) when GLFW and ImGui are found"
       ON)
if(TESSERA_DESKTOP_VIEWER)
  pkg_check_modules(GLFW3 IMPORTED_TARGET glfw3)
  # Debian's imgui.pc requires stb (ImGui's font rasteriser and rect packer).
  pkg_check_modules(IMGUI IMPORTED_TARGET imgui)
  if(GLFW3_FOUND AND IMGUI_FOUND)
    message(STATUS "tessera view: GLFW ${GLFW3_VERSION} + Dear ImGui ${IMGUI_VERSION}")
    target_compile_definitions(tessera_cli PRIVATE TESSERA_DESKTOP_VIEWER=1)
    # SYSTEM: ImGui's headers are not ours to keep free of warnings.
    target_include_directories(tessera_cli SYSTEM PRIVATE ${IMGUI_INCLUDE_DIRS})
    target_link_libraries(tessera_cli PRIVATE PkgConfig::GLFW3 PkgConfig::IMGUI ${CMAKE_DL_LIBS})
  else()
    message(STATUS "tessera view: off (needs libglfw3-dev and libimgui-dev)")
  endif()
endif()
