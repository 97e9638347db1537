#pragma once
// The one place that includes the GL ES headers for the engine's sources.
// gl3.h must come before gl2ext.h (it defines the API macros gl2ext uses).
// clang-format off
#include <GLES3/gl3.h>
#include <GLES2/gl2ext.h>
// clang-format on

#ifndef GL_R16_EXT
#define GL_R16_EXT 0x822A
#endif
