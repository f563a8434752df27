#!/usr/bin/env python3
"""Run a command that draws through GLX (Debian's ParaView: pvbatch) under a private virtual X
server, for the build's screenshot of chapter 7.

Usage:
    headless.py XVFB COMMAND [ARGUMENT...]

Starts `XVFB -displayfd FD -noreset -nolisten tcp`: the server itself picks a free display number
and writes it to FD once it accepts connections, so there is neither a race for the number nor a
wait of guessed length (as with xvfb-run -a); -noreset keeps it from resetting when its first
client disconnects, which made one pvbatch in six fail to connect ("bad X server connection")
on a loaded machine. The command runs with DISPLAY set to that server, which is stopped
afterwards. A command that fails is tried again, up to 3 times, each with a new server; the exit
code is the last try's. A command that exits with 2 (bad arguments or input, as
paraview_spheres.py does for a missing file) is not tried again: its message is what to read.
"""

import os
import select
import subprocess
import sys

ATTEMPTS = 3
START_TIMEOUT = 30.0  # seconds for the server to report its display


def start_server(xvfb):
    """The running server and its display (":N"); raises RuntimeError if it does not start."""
    read_end, write_end = os.pipe()
    server = subprocess.Popen(
        [xvfb, "-displayfd", str(write_end), "-noreset", "-nolisten", "tcp",
         "-screen", "0", "1280x1024x24"],
        pass_fds=(write_end,), stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    os.close(write_end)
    number = b""
    try:
        while not number.endswith(b"\n"):
            ready, _, _ = select.select([read_end], [], [], START_TIMEOUT)
            chunk = os.read(read_end, 32) if ready else b""
            if not chunk:
                break
            number += chunk
    finally:
        os.close(read_end)
    if not number.strip().isdigit():
        server.kill()
        _, error = server.communicate()
        raise RuntimeError(f"{xvfb} did not report a display within {START_TIMEOUT:g} s: "
                           f"{error.decode(errors='replace').strip()[-500:]}")
    return server, ":" + number.decode().strip()


def stop_server(server):
    server.terminate()
    try:
        server.wait(timeout=10)
    except subprocess.TimeoutExpired:
        server.kill()
        server.wait()


def main(argv):
    if len(argv) < 3:
        sys.stderr.write(__doc__)
        return 2
    xvfb, command = argv[1], argv[2:]
    code = 1
    for attempt in range(1, ATTEMPTS + 1):
        try:
            server, display = start_server(xvfb)
        except (OSError, RuntimeError) as error:
            sys.stderr.write(f"headless.py: attempt {attempt}: {error}\n")
            continue
        try:
            code = subprocess.call(command, env=dict(os.environ, DISPLAY=display))
        finally:
            stop_server(server)
        if code == 0:
            return 0
        if code == 2:  # the command refused its input or its arguments: a retry cannot help
            return 2
        sys.stderr.write(f"headless.py: attempt {attempt} of {ATTEMPTS}: {command[0]} exited with "
                         f"{code}\n")
    return code if code != 0 else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
