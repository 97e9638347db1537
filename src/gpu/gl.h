#pragma once
// The one place that includes the GL ES headers for the engine's sources.
#include <GLES2/gl2ext.h>
#include <GLES3/gl3.h>

#ifndef GL_R16_EXT
#define GL_R16_EXT 0x822A
#endif
