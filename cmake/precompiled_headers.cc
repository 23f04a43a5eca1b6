// Empty: the target exists to build the precompiled header
// (cmake/precompiled_headers.cmake) that the other targets reuse.
