file(REMOVE_RECURSE
  "libatmos_asan.a"
)
