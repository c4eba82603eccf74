# The sources of ffsr-optimize besides main.cpp, relative to src/cli; read by src/cli/CMakeLists.txt
# and by fuzz/CMakeLists.txt (fuzz_scenario compiles the support and some commands with the
# fuzzer's instrumentation).
#   support/   parsing flag values, loading the subject, the outputs (atomic writes), progress
#   commands/  one file per subcommand: parse -> compute -> report
#   figures/   every figure (plot.cpp draws with PLplot; the figures are built from the result structs)
set(FFSR_CLI_SUPPORT_SOURCES
    support/parse.cpp support/output.cpp support/progress.cpp support/scenario_flags.cpp support/subject.cpp)
set(FFSR_CLI_COMMAND_SOURCES
    commands/run.cpp commands/inspect.cpp commands/contact.cpp commands/xi.cpp commands/map.cpp
    commands/robust.cpp commands/pareto.cpp commands/closed_loop.cpp
    commands/detumble.cpp)
set(FFSR_CLI_FIGURE_SOURCES figures/capture.cpp figures/detumble.cpp figures/figures.cpp figures/plot.cpp)
