// tinygltf's implementation, compiled once (cps_tinygltf) for `cps export` and its test. The
// library's options (no image loading or writing) are the target's compile definitions.
#define TINYGLTF_IMPLEMENTATION
#include <tiny_gltf.h>
