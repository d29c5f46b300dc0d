# Writes OUT (fibernet_version.hpp) with the version and the commit being built, at every build, rewriting it only
# when it changes: results record the commit they were computed with (docs/scan.md), not the one CMake last saw.
execute_process(COMMAND git -C ${SRC} describe --always --dirty --abbrev=12
                OUTPUT_VARIABLE commit OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET RESULT_VARIABLE rc)
if(NOT rc EQUAL 0 OR NOT commit)
  set(commit "unknown")
endif()
set(text "#pragma once\n#define FIBERNET_VERSION \"${VERSION}\"\n#define FIBERNET_GIT_COMMIT \"${commit}\"\n")
if(EXISTS ${OUT})
  file(READ ${OUT} old)
else()
  set(old "")
endif()
if(NOT old STREQUAL text)
  file(WRITE ${OUT} "${text}")
endif()
