# Sourced by tools/setup.sh, tools/demo.sh and tools/test.sh (from the
# repository root). When a script runs through sudo on a clone that belongs to
# the user who called sudo, the steps after the package installation run as
# that user, so that build/, out/ and the test files stay theirs.

# Print the calling user and succeed when this is such a sudo run.
sudo_caller() {
  [ "$(id -u)" -eq 0 ] && [ -n "${SUDO_USER:-}" ] && [ "$SUDO_USER" != root ] &&
    [ "$(stat -c %U .)" = "$SUDO_USER" ] && echo "$SUDO_USER"
}

# Run the current script again as the calling user, with GRANARY_AS_CALLER=1
# (the script then skips the set-up it already did); returns in any other case.
rerun_as_caller() {
  local user
  if [ -z "${GRANARY_AS_CALLER:-}" ] && user=$(sudo_caller); then
    exec sudo -u "$user" -H env GRANARY_AS_CALLER=1 PATH="$PATH" bash "tools/$(basename "$0")" "$@"
  fi
}
