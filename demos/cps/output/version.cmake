# Run at every build (cmake -P, from demos/cps/CMakeLists.txt): writes OUTPUT, a header defining
# CPS_ENGINE_VERSION as `git describe --always --dirty` of SOURCE_DIR, or "unknown" outside git
# or without git. The header is replaced only when the text changes, so an unchanged version
# recompiles nothing.
set(version "unknown")
find_package(Git QUIET)
if(GIT_FOUND)
  execute_process(COMMAND "${GIT_EXECUTABLE}" describe --always --dirty
                  WORKING_DIRECTORY "${SOURCE_DIR}"
                  OUTPUT_VARIABLE described RESULT_VARIABLE status
                  OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  if(status EQUAL 0 AND NOT described STREQUAL "")
    set(version "${described}")
  endif()
endif()
string(REPLACE "\\" "\\\\" version "${version}")
string(REPLACE "\"" "\\\"" version "${version}")
file(WRITE "${OUTPUT}.new"
"// Generated at build time by demos/cps/version.cmake. Do not edit.
#pragma once
#define CPS_ENGINE_VERSION \"${version}\"
")
file(COPY_FILE "${OUTPUT}.new" "${OUTPUT}" ONLY_IF_DIFFERENT)
file(REMOVE "${OUTPUT}.new")
