# Writes ${OUT} with the git revision and dirtiness of ${SRC}; touches it only on change.
execute_process(COMMAND git -C "${SRC}" rev-parse HEAD OUTPUT_VARIABLE rev
                OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET RESULT_VARIABLE rc)
if(NOT rc EQUAL 0 OR rev STREQUAL "")
  set(rev "unknown")
endif()
# Dirty means the sources differ from the revision: results/ and plots/ are
# what make reproduce writes (deleting them to regenerate everything must not
# mark the code that regenerates them dirty).
execute_process(COMMAND git -C "${SRC}" status --porcelain --untracked-files=no -- .
                        ":(exclude)results" ":(exclude)plots"
                OUTPUT_VARIABLE st ERROR_QUIET RESULT_VARIABLE rc2)
if(rc2 EQUAL 0 AND st STREQUAL "")
  set(dirty "false")
else()
  set(dirty "true")
endif()
set(text "#pragma once\n#define NHI_GIT_REVISION \"${rev}\"\n#define NHI_GIT_DIRTY ${dirty}\n")
if(EXISTS "${OUT}")
  file(READ "${OUT}" old)
else()
  set(old "")
endif()
if(NOT old STREQUAL text)
  file(WRITE "${OUT}" "${text}")
endif()
