// Stress scenes: stiff and extreme cases (issue 4). Filled in with the stress scenes.
#include "scene.h"

#include <catch2/catch.hpp>
