# VOLMORPH_SANITIZE=address,undefined instruments project code. Undefined behaviour aborts
# (no recovery) so that a test run fails on the first report. -O1 -g1 come after the build type's
# flags and win: ASan's recommended level, line tables for its reports, and half the compile time of
# -O2 -g (a CLI unit: 29 s instead of 55 s), which keeps CI's sanitizer pass short on 2 cores.
function(volmorph_set_sanitizers target)
  if(VOLMORPH_SANITIZE)
    target_compile_options(${target} PRIVATE
      -fsanitize=${VOLMORPH_SANITIZE} -fno-sanitize-recover=all -fno-omit-frame-pointer -O1 -g1)
    target_link_options(${target} PRIVATE -fsanitize=${VOLMORPH_SANITIZE})
  endif()
endfunction()

# One call for every project target.
function(volmorph_configure_target target)
  volmorph_set_warnings(${target})
  volmorph_set_sanitizers(${target})
endfunction()
