# Control characters a scene or the command line carries (in a title, a table's name, an --out
# path) reach the terminal in caret notation ("^[" for an escape), never raw: a title could
# otherwise clear the screen, or fake a line of the report.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
string(ASCII 27 esc)
string(ASCII 7 bell)

# Runs clothlab with the arguments after `code`, expects exit code `code` and no control
# character in what it prints but the line ends (10); sets `out` and `err` for the caller.
function(run_clothlab what code)
  execute_process(COMMAND ${CLOTHLAB} ${ARGN} RESULT_VARIABLE result ERROR_VARIABLE stderr
                  OUTPUT_VARIABLE stdout)
  if(NOT result EQUAL code)
    message(FATAL_ERROR "${what}: expected exit code ${code}, got ${result}\n${stdout}${stderr}")
  endif()
  foreach(control RANGE 1 127)
    if(control LESS 32 AND NOT control EQUAL 10 OR control EQUAL 127)
      string(ASCII ${control} char)
      string(FIND "${stdout}${stderr}" "${char}" at)
      if(NOT at EQUAL -1)
        message(FATAL_ERROR "${what}: control character ${control} reached the terminal:\n"
                            "${stdout}${stderr}")
      endif()
    endif()
  endforeach()
  set(out "${stdout}" PARENT_SCOPE)
  set(err "${stderr}" PARENT_SCOPE)
endfunction()

# Fails unless `text` holds `expected`, as written.
function(expect_text what text expected)
  string(FIND "${text}" "${expected}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "${what}: expected '${expected}' in:\n${text}")
  endif()
endfunction()

# The title, in TOML's escapes: an escape sequence that clears the screen, a bell, a newline that
# would start a line of its own.
file(WRITE ${WORK}/title.toml "title = \"a\\u001b[2Jb\\u0007c\\nerror: fake\"
[[particle]]
position = [0, 0, 0]
mass = 1
[integrator]
dt = 0.1
duration = 0.2
")
run_clothlab("run" 0 run ${WORK}/title.toml --out "${WORK}/out${esc}[31m")
foreach(expected "title.toml - a^[[2Jb^Gc\\nerror: fake\n" "/out^[[31m/: energy.csv"
                 "/out^[[31m/view.html in a browser")
  expect_text("run" "${out}" "${expected}")
endforeach()

# A table's name, quoted so that it can hold anything, in the error that refuses it.
file(WRITE ${WORK}/table.toml "[\"x\\u001b]0;title\\u0007\"]\n")
run_clothlab("validate, a table's name" 2 validate ${WORK}/table.toml)
expect_text("validate, a table's name" "${err}" "unknown table [x^[]0;title^G]")
# A NUL among them, shown as ^@: it once ended the message there, and what was expected was lost.
file(WRITE ${WORK}/nul.toml "[\"x\\u0000y\\u001b\"]\n")
run_clothlab("validate, a table's name with a NUL" 2 validate ${WORK}/nul.toml)
expect_text("validate, a table's name with a NUL" "${err}"
            "unknown table [x^@y^[]; expected one of: ")

# The scene's path in validate's report.
set(named "${WORK}/scene${bell}.toml")
file(COPY_FILE ${WORK}/title.toml "${named}")
run_clothlab("validate, a path" 0 validate "${named}")
expect_text("validate, a path" "${out}" "scene^G.toml: ok: 1 particle")
