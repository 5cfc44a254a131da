# Every dependency comes from a Debian package (see ./x for the list).
find_package(PkgConfig REQUIRED)
find_package(Threads REQUIRED)
find_package(Vulkan REQUIRED)
find_package(glm REQUIRED)
find_package(nlohmann_json 3 REQUIRED)
pkg_check_modules(STB REQUIRED IMPORTED_TARGET stb)
find_program(GLSLANG_VALIDATOR glslangValidator REQUIRED)
