# Scenes that once crashed `validate` and `run` in the TOML reader (SIGSEGV, exit 139): each ends
# with exit code 2 and a FILE:LINE:COL message, whatever the shell's stack limit.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})

function(expect_refusal what scene message)
  foreach(command validate run)
    set(args ${command} ${scene})
    if(command STREQUAL "run")
      list(APPEND args --out ${WORK}/out --no-html)
    endif()
    # 256 KiB of stack, a thirty-second of the usual 8 MiB: the reader must not depend on it.
    execute_process(COMMAND sh -c "ulimit -s 256 && exec \"$0\" \"$@\"" ${CLOTHLAB} ${args}
                    RESULT_VARIABLE code ERROR_VARIABLE err OUTPUT_VARIABLE out)
    if(NOT code EQUAL 2)
      message(FATAL_ERROR "${what}, ${command}: expected exit code 2, got ${code}\n${out}${err}")
    endif()
    if(NOT err MATCHES "${message}")
      message(FATAL_ERROR "${what}, ${command}: expected '${message}' in:\n${err}")
    endif()
  endforeach()
endfunction()

# A dotted key of 40,000 parts after a multi-line string that ends in an extra quote.
expect_refusal("a key after \"\"\"a\"\"\"\""
               ${SCENES}/bad/deep_key_after_multiline_string.toml
               "deep_key_after_multiline_string.toml:3:130: the parts of a dotted key nest more than 64 deep")
expect_refusal("a key after '''a''''"
               ${SCENES}/bad/deep_key_after_multiline_literal.toml
               "deep_key_after_multiline_literal.toml:3:130: the parts of a dotted key nest more than 64 deep")

# The deepest scene the nesting check lets through: a 65-part table header, then 64 inline
# tables in each other, each with a 65-part key (about 4,300 levels). The TOML reader reads it
# whole on a stack of its own; the scene is then refused for its unknown table.
string(REPEAT ".a" 64 rest)
set(part "a${rest}")
set(value "1")
foreach(k RANGE 1 63)
  set(value "{${part} = ${value}}")
endforeach()
file(WRITE ${WORK}/deepest.toml "[${part}]\n${part} = ${value}\n")
expect_refusal("the deepest scene let through" ${WORK}/deepest.toml
               "deepest.toml:1:2: unknown table \\[a\\]")
