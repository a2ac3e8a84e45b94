# VOLMORPH_SANITIZE=address,undefined instruments project code. Undefined behaviour aborts
# (no recovery) so that a test run fails on the first report.
function(volmorph_set_sanitizers target)
  if(VOLMORPH_SANITIZE)
    target_compile_options(${target} PRIVATE
      -fsanitize=${VOLMORPH_SANITIZE} -fno-sanitize-recover=all -fno-omit-frame-pointer -g)
    target_link_options(${target} PRIVATE -fsanitize=${VOLMORPH_SANITIZE})
  endif()
endfunction()

# One call for every project target.
function(volmorph_configure_target target)
  volmorph_set_warnings(${target})
  volmorph_set_sanitizers(${target})
endfunction()
