# Embedding of build-time artefacts (SPIR-V, data files) into binaries as byte arrays.

# fovea_embed_files(TARGET target NAMESPACE ns FILES f1 f2 ...)
# Generates a source with `std::span<const std::uint8_t> ns::find(std::string_view name)`
# returning the bytes of the file whose base name is `name` (empty span if absent),
# and `ns::names()` listing them. Files are re-embedded when they change.
function(fovea_embed_files)
  cmake_parse_arguments(E "" "TARGET;NAMESPACE" "FILES" ${ARGN})
  set(out ${CMAKE_CURRENT_BINARY_DIR}/${E_TARGET}_embedded.cpp)
  add_custom_command(
    OUTPUT ${out}
    COMMAND ${CMAKE_COMMAND} -DOUT=${out} -DNS=${E_NAMESPACE} "-DFILES=${E_FILES}"
            -P ${PROJECT_SOURCE_DIR}/cmake/embed_files.cmake
    DEPENDS ${E_FILES} ${PROJECT_SOURCE_DIR}/cmake/embed_files.cmake
    COMMENT "Embedding ${E_TARGET}"
    VERBATIM)
  add_library(${E_TARGET} STATIC ${out})
  target_compile_features(${E_TARGET} PUBLIC cxx_std_20)
endfunction()
