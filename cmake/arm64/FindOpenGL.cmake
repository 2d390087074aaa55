# The cross build's answer to find_package(OpenGL): MuJoCo's CMake package
# asks for OpenGL (find_dependency), although libmujoco links none of it and
# nothing in the runtime draws. Found, with no targets and no libraries, so
# that the arm64 sysroot needs no Mesa and no LLVM (packaging/arm64-sysroot);
# a target that linked OpenGL::GL would fail to configure.
set(OpenGL_FOUND TRUE)
set(OPENGL_FOUND TRUE)
