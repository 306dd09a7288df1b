file(REMOVE_RECURSE
  "libatmos_static.a"
)
