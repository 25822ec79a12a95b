// The translation unit that carries the precompiled Catch2 header
// (tests/CMakeLists.txt); it defines nothing.
