#!/usr/bin/env bash
# The browser test of the instrument page, as CTest runs it:
#   run.sh CIA402_BINARY WORK_DIR SCREENSHOT_PNG   (SCREENSHOT_PNG, and three more pictures beside
#                                                  it, are written with CIA402_UPDATE_SCREENSHOT=1)
# Then scope.test.mjs, the scope's checks, on a server of its own; homing, parameters and the jog's
# dead-man (jog.test.mjs) after it.
# Then scope.test.mjs, the scope's checks, on a server of its own, and scope_can.test.mjs, the same
# on a drive behind `cia402 serve --can`.
# Installs playwright-core with `npm ci` from this folder's package-lock.json into WORK_DIR (no
# browser download: Debian's /usr/bin/chromium is used), then runs instrument_page.test.mjs.
# Exit 77 (CTest: skipped) with the reason printed when node, npm or chromium is missing, or when
# npm ci cannot install (no registry).
set -euo pipefail

cia402=${1:?usage: run.sh CIA402_BINARY WORK_DIR SCREENSHOT_PNG}
work=${2:?usage: run.sh CIA402_BINARY WORK_DIR SCREENSHOT_PNG}
screenshot=${3:?usage: run.sh CIA402_BINARY WORK_DIR SCREENSHOT_PNG}
here=$(cd "$(dirname "$0")" && pwd)
chromium=${CIA402_CHROMIUM:-/usr/bin/chromium}

skip() { echo "SKIPPED: $*"; exit 77; }
command -v node >/dev/null || skip "node is not installed (apt-get install nodejs npm)"
command -v npm >/dev/null || skip "npm is not installed (apt-get install npm)"
[ -x "$chromium" ] || skip "$chromium is missing (apt-get install chromium)"

mkdir -p "$work"
# Reinstall only when the lock file changed. Each script is a CTest of its own and they run side by
# side: the first installs, under this lock, and the others wait for it.
exec 9>"$work/.install.lock"
flock 9
if ! cmp -s "$here/package-lock.json" "$work/package-lock.json" || [ ! -d "$work/node_modules/playwright-core" ]; then
  cp "$here/package.json" "$here/package-lock.json" "$work/"
  if ! (cd "$work" && PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD=1 npm ci --no-audit --no-fund --loglevel=error); then
    rm -f "$work/package-lock.json"
    skip "npm ci could not install playwright-core (no access to the npm registry?)"
  fi
fi
flock -u 9

# The screenshot in docs/ changes only when asked for (CIA402_UPDATE_SCREENSHOT=1), so a test run
# leaves the source tree as it was; otherwise it goes beside the other outputs.
if [ "${CIA402_UPDATE_SCREENSHOT:-0}" != 1 ]; then
  screenshot="$work/output/instrument-page.png"
fi

export CIA402_NODE_MODULES="$work/node_modules"
export CIA402_CHROMIUM="$chromium"
# CIA402_BROWSER_ONLY=control.test.mjs: that script alone (how CTest runs each, see
# tests/page/CMakeLists.txt); the instrument page's script also takes the screenshot's path.
if [ -n "${CIA402_BROWSER_ONLY:-}" ]; then
  if [ "$CIA402_BROWSER_ONLY" = instrument_page.test.mjs ]; then
    exec node "$here/$CIA402_BROWSER_ONLY" "$cia402" "$work/output" "$screenshot"
  fi
  exec node "$here/$CIA402_BROWSER_ONLY" "$cia402" "$work/output"
fi
node "$here/instrument_page.test.mjs" "$cia402" "$work/output" "$screenshot"
node "$here/instrument_page_servers.test.mjs" "$cia402" "$work/output"
node "$here/scope.test.mjs" "$cia402" "$work/output"
node "$here/scope_can.test.mjs" "$cia402" "$work/output"
node "$here/homing.test.mjs" "$cia402" "$work/output"
node "$here/parameters.test.mjs" "$cia402" "$work/output"
node "$here/jog.test.mjs" "$cia402" "$work/output"
# With CIA402_UPDATE_SCREENSHOT=1 the docs' other pictures follow: phone width, several axes, the
# recorder (the whole page at 1280 px), profile position after a move.
if [ "${CIA402_UPDATE_SCREENSHOT:-0}" = 1 ]; then
  images=$(dirname "$screenshot")
  cp "$work/output/phone-390x844.png" "$images/instrument-page-phone.png"
  cp "$work/output/axes-1280x800.png" "$images/axes.png"
  cp "$work/output/full-1280.png" "$images/instrument-page-full.png"
  cp "$work/output/pp-1280x800.png" "$images/instrument-page-pp.png"
  cp "$work/output/scope-1280.png" "$images/instrument-page-scope.png"
  node "$here/panel_pictures.mjs" "$cia402" "$work/output" "$images"
fi
