file(REMOVE_RECURSE
  "libcairn.a"
)
