// fuzz_tinygltf.cpp — tinygltf compiled into the glTF harness from the
// header Debian's libtinygltf is built from (same options: its JSON parser
// and the stb loaders), so the fuzzer sees its branches; the product links
// libtinygltf.
#define TINYGLTF_IMPLEMENTATION
#include <tiny_gltf.h>
