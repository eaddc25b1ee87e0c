// The one place the OpenGL loader is included (GLAD 2, generated at configure time).
#pragma once

#include <glad/gl.h>
