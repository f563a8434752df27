# Shared by scripts/check and scripts/demo (sourced, not run).

# Run a command as the user who invoked sudo, so that a `sudo scripts/check` does not leave a
# build tree that only root can write; as plain root or a plain user, run it as is.
as_user() {
  if [[ $(id -u) -eq 0 && -n "${SUDO_USER:-}" && "${SUDO_USER}" != root ]]; then
    sudo -u "$SUDO_USER" -- "$@"
  else
    "$@"
  fi
}

# Open MPI refuses to start as root unless told that this is intended.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
