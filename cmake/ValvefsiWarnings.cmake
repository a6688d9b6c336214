# Our own targets link valvefsi::warnings; generated code (protobuf) does not.
add_library(valvefsi_warnings INTERFACE)
add_library(valvefsi::warnings ALIAS valvefsi_warnings)
target_compile_options(valvefsi_warnings INTERFACE -Wall -Wextra -Wpedantic)
