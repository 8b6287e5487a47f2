#!/usr/bin/env bash
# The README's promise on fresh Debian 12 machines: builds minimal Debian 12
# roots with debootstrap, clones this repository (its committed HEAD) into each,
# and runs the README's two commands verbatim inside with chroot:
#   root "fresh":    a bare debootstrap root; the commands run as root; then
#                    tools/setup.sh once more, which must install nothing;
#   root "paraview": paraview and python3-paraview installed first, as a user
#                    does to look at dumps; the commands run by an ordinary
#                    user through sudo ("sudo " + the command); afterwards no
#                    package that was installed before may be missing.
# Prints pass/fail and the wall time of every command, and a summary.
# Needs root, debootstrap and network access to the Debian mirror this machine
# uses (read from its apt sources). Takes about an hour per root on 2 cores.
#
# Usage: tools/check_fresh_machine.sh [--dir DIR] [--only fresh|paraview] [--keep]
#   --dir DIR   where the roots are built (default /var/tmp/granary-fresh; wiped first)
#   --only R    check one root only
#   --keep      leave the roots in place (default: removed after a pass)
# Logs: DIR/<root>.log (everything the commands printed).
set -uo pipefail
REPO="$(cd "$(dirname "$0")/.." && pwd)"
DIR=/var/tmp/granary-fresh
ONLY=""
KEEP=0
while [ $# -gt 0 ]; do
  case "$1" in
    --dir) DIR="$2"; shift 2 ;;
    --only) ONLY="$2"; shift 2 ;;
    --keep) KEEP=1; shift ;;
    -h|--help) sed -n '2,21p' "$0"; exit 0 ;;
    *) echo "check_fresh_machine: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
[ "$(id -u)" -eq 0 ] || { echo "check_fresh_machine: run as root (debootstrap, chroot, mount)" >&2; exit 2; }
command -v debootstrap >/dev/null || { echo "check_fresh_machine: install debootstrap (apt-get install debootstrap)" >&2; exit 2; }

# The README's two commands: the single-line code blocks of its section
# "Two commands on a fresh Debian 12 machine", in order.
mapfile -t COMMANDS < <(awk '
  /^## / { insec = ($0 ~ /^## Two commands/) ; next }
  insec && /^```/ { inblock = !inblock; next }
  insec && inblock && NF { print }' "$REPO/README.md")
if [ ${#COMMANDS[@]} -ne 2 ]; then
  echo "check_fresh_machine: expected two commands in README.md's 'Two commands' section, found ${#COMMANDS[@]}" >&2
  exit 2
fi

# Mirror and suites of this machine's Debian sources (bookworm, bookworm-updates, bookworm-security).
mapfile -t SOURCES < <(apt-get indextargets --format '$(REPO_URI) $(RELEASE)' 'Created-By: Packages' 2>/dev/null |
                       awk '$2 ~ /^bookworm/' | sort -u)
MIRROR=$(printf '%s\n' "${SOURCES[@]}" | awk '$2 == "bookworm" { print $1; exit }')
[ -n "$MIRROR" ] || { echo "check_fresh_machine: no bookworm source in this machine's apt sources" >&2; exit 2; }

COMMIT=$(git -C "$REPO" rev-parse --short HEAD)
COMMIT_FULL=$(git -C "$REPO" rev-parse HEAD)   # both roots check this commit, even if HEAD moves meanwhile
echo "check_fresh_machine: repository $REPO at $COMMIT; mirror $MIRROR"
for c in "${COMMANDS[@]}"; do echo "  README command: $c"; done
[ -z "$(git -C "$REPO" status --porcelain --untracked-files=no)" ] ||
  echo "  note: uncommitted changes are not part of the check (the clones hold HEAD as it was at the start)"

RESULTS=()
MOUNTED=()
cleanup_mounts() {
  local i
  for ((i = ${#MOUNTED[@]} - 1; i >= 0; i--)); do umount -l "${MOUNTED[$i]}" 2>/dev/null; done
  MOUNTED=()
}
trap cleanup_mounts EXIT

# step NAME LOG COMMAND...: run, time, record pass/fail
step() {
  local name="$1" log="$2"; shift 2
  local t0=$SECONDS rc
  echo "---- $name" >> "$log"
  "$@" >> "$log" 2>&1
  rc=$?
  local dt=$((SECONDS - t0))
  local verdict=PASS
  [ $rc -eq 0 ] || verdict="FAIL (exit $rc)"
  RESULTS+=("$(printf '%-58s %-14s %6d s' "$name" "$verdict" "$dt")")
  echo "  $(printf '%-58s %-14s %6d s' "$name" "$verdict" "$dt")"
  return $rc
}

make_root() {
  local root="$1" log="$2"
  rm -rf "$root"
  mkdir -p "$root"
  step "debootstrap --variant=minbase bookworm" "$log" \
    debootstrap --variant=minbase bookworm "$root" "$MIRROR" || return 1
  printf 'deb %s %s main\n' $(printf '%s\n' "${SOURCES[@]}") > "$root/etc/apt/sources.list"
  # what the Debian installer leaves on every machine: name service and the host's own name
  cp /etc/resolv.conf "$root/etc/resolv.conf"
  printf '127.0.0.1\tlocalhost\n127.0.1.1\t%s\n::1\tlocalhost ip6-localhost ip6-loopback\n' "$(hostname)" \
    > "$root/etc/hosts"
  mount -t proc proc "$root/proc" && MOUNTED+=("$root/proc")
  mount --bind /dev "$root/dev" && MOUNTED+=("$root/dev")
  mount -t tmpfs -o mode=1777 tmpfs "$root/dev/shm" && MOUNTED+=("$root/dev/shm")
  mount --bind /sys "$root/sys" && MOUNTED+=("$root/sys")
}

# home ROOT USER: the user's home folder inside the root
home_of() { chroot "$1" getent passwd "$2" | cut -d: -f6; }

# in_root ROOT USER COMMAND: a login-like shell in the clone
in_root() {
  local root="$1" user="$2" cmd="$3" home
  home=$(home_of "$root" "$user")
  chroot "$root" /usr/bin/env -i HOME="$home" USER="$user" LANG=C.UTF-8 \
    PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
    /bin/su -s /bin/bash "$user" -c "cd $home/granary && $cmd"
}

installed_packages() { chroot "$1" dpkg-query -W -f='${Package} ${Status}\n' | awk '/install ok installed/ { print $1 }' | sort; }

check_root() {
  local name="$1" root="$DIR/$1" log="$DIR/$1.log" user=root prefix="" ok=0
  echo "== root '$name' ($root, log $log)"
  : > "$log"
  make_root "$root" "$log" || { cleanup_mounts; return 1; }
  if [ "$name" = paraview ]; then
    step "apt-get install paraview python3-paraview sudo (before)" "$log" \
      chroot "$root" /usr/bin/env DEBIAN_FRONTEND=noninteractive bash -c \
      "apt-get update && apt-get install -y paraview python3-paraview sudo" || ok=1
    chroot "$root" useradd -m -s /bin/bash granary
    echo "granary ALL=(ALL) NOPASSWD: ALL" > "$root/etc/sudoers.d/granary"
    user=granary prefix="sudo "
  fi
  local home
  home=$(home_of "$root" "$user")
  installed_packages "$root" > "$DIR/$name.before"
  git clone -q "$REPO" "$root$home/granary" && git -C "$root$home/granary" checkout -q "$COMMIT_FULL"
  chroot "$root" chown -R "$user:" "$home/granary"
  for c in "${COMMANDS[@]}"; do
    step "[$name] as $user: $prefix$c" "$log" in_root "$root" "$user" "$prefix$c" || ok=1
  done
  if [ "$name" = fresh ]; then
    # run again: nothing to install, nothing reinstalled
    step "[$name] tools/setup.sh again (idempotent)" "$log" \
      in_root "$root" "$user" "bash tools/setup.sh > setup-again.log 2>&1 && grep -q 'all packages present' setup-again.log && ! grep -q 'apt-get\|Unpacking' setup-again.log" || ok=1
  fi
  installed_packages "$root" > "$DIR/$name.after"
  local removed
  removed=$(comm -23 "$DIR/$name.before" "$DIR/$name.after")
  if [ -n "$removed" ]; then
    RESULTS+=("$(printf '%-58s %-14s' "[$name] no package removed" "FAIL: $removed")")
    echo "  packages removed: $removed"
    ok=1
  else
    RESULTS+=("$(printf '%-58s %-14s' "[$name] no package removed" PASS)")
  fi
  # the demo's outputs and the test summary
  grep -E "tests passed|tests failed|Total Test time" "$log" | tail -3 | sed 's/^/  /'
  cleanup_mounts
  [ $ok -eq 0 ] && [ $KEEP -eq 0 ] && rm -rf "$root"
  return $ok
}

mkdir -p "$DIR"
status=0
for r in fresh paraview; do
  [ -z "$ONLY" ] || [ "$ONLY" = "$r" ] || continue
  check_root "$r" || status=1
done
echo "== summary (repository at $COMMIT)"
printf '  %s\n' "${RESULTS[@]}"
[ $status -eq 0 ] && echo "check_fresh_machine: PASS" || echo "check_fresh_machine: FAIL (logs in $DIR)"
exit $status
