# Writes OUT (boxd.1) with help2man from BOXD's --help and --version, and every subcommand's
# --help in a COMMANDS section, so that `man boxd` holds the whole command line.
execute_process(COMMAND ${BOXD} --help OUTPUT_VARIABLE top RESULT_VARIABLE failed)
if(failed)
    message(FATAL_ERROR "${BOXD} --help failed")
endif()
string(REGEX MATCH "Subcommands:\n(.*)" listing "${top}")
string(REGEX MATCHALL "\n  [a-z][a-z-]+" names "\n${CMAKE_MATCH_1}")
set(include "[COMMANDS]\n")
foreach(name ${names})
    string(STRIP "${name}" name)
    execute_process(COMMAND ${BOXD} ${name} --help OUTPUT_VARIABLE help)
    # roff: a backslash is \e, a line starting with a dot or a quote is escaped with \&.
    string(REPLACE "\\" "\\e" help "${help}")
    string(REGEX REPLACE "\n([.'])" "\n\\\\&\\1" help "\n${help}")
    string(APPEND include ".SS \"boxd ${name}\"\n.nf${help}\n.fi\n")
endforeach()
string(APPEND include "[SEE ALSO]\n/usr/share/doc/boxd/README.md and the documentation in\n"
                      "/usr/share/doc/boxd/docs/ (the daemon, the station, measuring, limits).\n")
file(WRITE ${OUT}.h2m "${include}")
execute_process(
    COMMAND ${HELP2MAN} --no-info --section=1 --source=boxd
            "--name=measures parcels on a turntable with a depth camera"
            --include=${OUT}.h2m --output=${OUT} ${BOXD}
    RESULT_VARIABLE failed)
if(failed)
    message(FATAL_ERROR "help2man failed on ${BOXD}")
endif()
