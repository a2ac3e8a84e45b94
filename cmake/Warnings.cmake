# Strict warnings for volmorph's own code. Dependency headers come in as SYSTEM includes (imported
# targets do that by default), so their warnings never fail our build.
function(volmorph_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Werror)
endfunction()
