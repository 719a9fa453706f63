// tinygltf's implementation, compiled here from the header Debian ships
// (libtinygltf-dev), rather than linked from libtinygltf.so: that library
// pulls the shared libstdc++ into the `sylva` process, which links its C++
// runtime statically to start in half the time (bench/startup.sh). Sylva
// writes no images, so tinygltf's stb image support is left out.
#define TINYGLTF_IMPLEMENTATION
#include <tiny_gltf.h>
