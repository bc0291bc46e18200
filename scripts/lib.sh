# Shared helpers of scripts/run and scripts/test: install what the firmware needs, once.
# Sourced, not executed. Every function is idempotent and prints what it does.

export PATH="${CARGO_HOME:-$HOME/.cargo}/bin:$PATH"

say() { printf '%s\n' "$*" >&2; }

# The Rust toolchain, its Cortex-M4F target and components, as pinned by rust-toolchain.toml.
ensure_toolchain() {
  if ! command -v rustup >/dev/null 2>&1; then
    say "rustup is missing: install it (https://rustup.rs), then run this again."
    return 1
  fi
  # Reads rust-toolchain.toml and installs the toolchain, targets and components it lists.
  rustup toolchain install >/dev/null 2>&1 || rustup toolchain install
}

# The URI of the system's Debian mirror for bookworm, read from its own apt sources (deb822 or
# one-line format), so that backports come from the mirror the machine already uses.
debian_mirror() {
  local f
  for f in /etc/apt/sources.list.d/*.sources; do
    [ -f "$f" ] || continue
    awk 'BEGIN{RS=""; FS="\n"}
         { uri=""; ok=0
           for (i=1;i<=NF;i++) {
             if ($i ~ /^URIs:/) { split($i, a, /[ \t]+/); uri=a[2] }
             if ($i ~ /^Suites:/ && $i ~ /[ \t]bookworm([ \t]|$)/) ok=1 }
           if (ok && uri != "") { print uri; exit } }' "$f"
  done | head -n 1
  for f in /etc/apt/sources.list /etc/apt/sources.list.d/*.list; do
    [ -f "$f" ] || continue
    sed -nE 's/^deb[ \t]+(\[[^]]*\][ \t]+)?([^ \t]+)[ \t]+bookworm([ \t].*)?$/\2/p' "$f"
  done | head -n 1
}

# qemu-system-arm with the mps2-an386 machine. Installs QEMU 10 from bookworm-backports when no
# QEMU is present (as root; otherwise prints the exact commands and fails).
ensure_qemu() {
  if command -v qemu-system-arm >/dev/null 2>&1 &&
    qemu-system-arm -machine help 2>/dev/null | grep -q '^mps2-an386'; then
    return 0
  fi
  local mirror dir
  mirror="$(debian_mirror | head -n 1)"
  if [ -z "$mirror" ]; then
    say "qemu-system-arm is missing and no Debian bookworm mirror was found in /etc/apt."
    say "Install qemu-system-arm (version 8 or later, with the mps2-an386 machine) and run this again."
    return 1
  fi
  dir="$(mktemp -d)"
  cp /etc/apt/sources.list.d/*.sources /etc/apt/sources.list.d/*.list "$dir"/ 2>/dev/null || true
  if [ -f /etc/apt/sources.list ]; then cp /etc/apt/sources.list "$dir/system.list"; fi
  cat >"$dir/sonolube-backports.sources" <<SRC
Types: deb
URIs: $mirror
Suites: bookworm-backports
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
SRC
  local opts="-o Dir::Etc::SourceList=/dev/null -o Dir::Etc::SourceParts=$dir"
  local install="apt-get $opts -y -t bookworm-backports install --no-install-recommends qemu-system-arm"
  if [ "$(id -u)" != 0 ]; then
    say "qemu-system-arm is missing. As root, run:"
    say "  apt-get $opts update && $install"
    say "(the directory $dir holds your apt sources plus bookworm-backports)"
    return 1
  fi
  say "installing qemu-system-arm from bookworm-backports ($mirror)"
  # shellcheck disable=SC2086
  apt-get $opts update -qq && DEBIAN_FRONTEND=noninteractive $install -qq >/dev/null
  rm -rf "$dir"
  qemu-system-arm --version | head -n 1 >&2
}

# defmt-print, the host decoder of the firmware's defmt log (same major version as defmt).
ensure_defmt_print() {
  if command -v defmt-print >/dev/null 2>&1; then
    return 0
  fi
  say "installing defmt-print (cargo install, about 1.5 min)"
  cargo install defmt-print --locked --version '^1' --quiet
}

# Everything the QEMU board needs.
ensure_qemu_tools() {
  ensure_toolchain && ensure_qemu && ensure_defmt_print
}

# cargo-mutants, the mutation tester of scripts/mutants (pinned: its output format and the
# mutants it generates change between versions, and docs/testing.md quotes its counts).
CARGO_MUTANTS_VERSION=27.1.0
ensure_cargo_mutants() {
  if command -v cargo-mutants >/dev/null 2>&1 &&
    cargo mutants --version 2>/dev/null | grep -qF "$CARGO_MUTANTS_VERSION"; then
    return 0
  fi
  say "installing cargo-mutants $CARGO_MUTANTS_VERSION (cargo install --locked, about 3 min)"
  cargo install cargo-mutants --locked --version "=$CARGO_MUTANTS_VERSION" --quiet
}
