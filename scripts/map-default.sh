#!/usr/bin/env bash
# Quick start 1: set up, build, and run elevation-mapper on the shipped default data.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
source "$root/scripts/setup.sh"
cd "$root"
"$build_dir/apps/elevation-mapper/elevation-mapper" "$@"
