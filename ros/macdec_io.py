"""Bounded, deadlined I/O for the ROS nodes (macdec issue 29 class 7), without rospy, so it is
tested by plain `python3 -m unittest discover -s ros` (ros/test_macdec_io.py).

- `LineChannel`: lines from a pipe or socket, each at most `max_bytes` long, each within a
  deadline (a peer trickling one byte at a time does not extend it).
- `write_all`: a whole message to a pipe or socket before a deadline.
- `PolicyProcess`: a `macdec robot` child over stdin/stdout; a reply that is not complete within
  the timeout kills and restarts the child instead of hanging the node.
- `RobotSession`: what a robot node asks of that child: observations with the primitive step
  they were made at (counted here: a ROS message carries none), resets.
- `read_manifest`: a policy directory's `policy.json` (or an older export's `manifest.json`),
  a regular file of at most 1 MiB, as macdec itself reads it.
- `owns_connection`: whether a TCP connection accepted here comes from a given process (Linux
  /proc), so the domain bridge serves only the `macdec domain` it started.
"""

import json
import os
import select
import stat
import subprocess
import sys
import threading
import time

#: Longest reply line read from `macdec robot` (its info reply carries the manifest): 16 MiB,
#: the bound macdec's own driver puts on replies.
MAX_REPLY_BYTES = 16 * 1024 * 1024
#: macdec robot's default longest request line (`--max-line-bytes`), in bytes.
DEFAULT_MAX_LINE_BYTES = 64 * 1024
#: Longest policy.json / manifest.json read, as in macdec (README "Limits and guarantees").
MAX_MANIFEST_BYTES = 1024 * 1024


class LineTimeout(Exception):
    """The line (or the write) did not complete before its deadline."""


class LineTooLong(Exception):
    """A line passed its byte limit before its newline."""


def _left(deadline):
    """Seconds until `deadline` (a time.monotonic() value; None: no deadline)."""
    if deadline is None:
        return None
    left = deadline - time.monotonic()
    if left <= 0:
        raise LineTimeout()
    return left


class LineChannel:
    """Lines from a file descriptor (a pipe or a socket), each at most `max_bytes` bytes before
    its newline. The fd is read with select, so a deadline holds however the peer paces bytes."""

    def __init__(self, fd, max_bytes):
        self.fd = fd
        self.max_bytes = max_bytes
        self.buffer = bytearray()

    def read_line(self, deadline=None):
        """The next line (bytes, without `\\n` and a trailing `\\r`), or None at the end of input
        (an unterminated last line is dropped). LineTimeout once `deadline` (time.monotonic())
        passes; LineTooLong for a line longer than max_bytes (the channel is then unusable)."""
        while True:
            end = self.buffer.find(b"\n")
            if end >= 0:
                if end > self.max_bytes:
                    raise LineTooLong()
                line = bytes(self.buffer[:end])
                del self.buffer[: end + 1]
                return line[:-1] if line.endswith(b"\r") else line
            if len(self.buffer) > self.max_bytes:
                raise LineTooLong()
            ready, _, _ = select.select([self.fd], [], [], _left(deadline))
            if not ready:
                raise LineTimeout()
            chunk = os.read(self.fd, 65536)
            if not chunk:
                self.buffer.clear()
                return None
            self.buffer += chunk


def write_all(fd, data, deadline=None):
    """Write all of `data` to the non-blocking fd before `deadline`, or LineTimeout."""
    view = memoryview(data)
    while view:
        _, ready, _ = select.select([], [fd], [], _left(deadline))
        if not ready:
            raise LineTimeout()
        try:
            view = view[os.write(fd, view) :]
        except BlockingIOError:
            continue


class PolicyProcess:
    """`macdec robot` over stdin/stdout: one request line out, one reply line back, under a lock
    (rospy runs each subscription's callbacks on its own thread). Writing a request and reading
    its whole reply must take at most `timeout_secs`; replies are at most MAX_REPLY_BYTES."""

    def __init__(self, command, timeout_secs, max_reply_bytes=MAX_REPLY_BYTES):
        self.command = command
        self.timeout_secs = timeout_secs
        self.max_reply_bytes = max_reply_bytes
        self.lock = threading.Lock()
        self.child = None
        self.lines = None
        self.start()

    def start(self):
        self.child = subprocess.Popen(
            self.command, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=sys.stderr
        )
        os.set_blocking(self.child.stdin.fileno(), False)
        self.lines = LineChannel(self.child.stdout.fileno(), self.max_reply_bytes)

    def request(self, message, restart=True):
        """The reply (a dict) to `message` (a dict). If the child is gone, or has not replied in
        time, a RuntimeError says so, and with `restart` the child is started again (its hidden
        state is then zero; a late reply must never be taken for the next request's)."""
        line = (json.dumps(message, allow_nan=True) + "\n").encode()
        with self.lock:
            deadline = time.monotonic() + self.timeout_secs
            problem = None
            try:
                write_all(self.child.stdin.fileno(), line, deadline)
                reply = self.lines.read_line(deadline)
            except LineTimeout:
                problem = "gave no complete reply within %g s" % self.timeout_secs
            except LineTooLong:
                problem = "sent a reply longer than %d bytes" % self.max_reply_bytes
            except (BrokenPipeError, OSError, ValueError):
                reply = None
            if problem is None and reply is None:
                self.stop()
                problem = "exited (status %s)" % self.child.returncode
            elif problem is not None:
                self.stop(kill=True)
            if problem is not None:
                if not restart:
                    raise RuntimeError("macdec robot %s" % problem)
                self.start()
                raise RuntimeError(
                    "macdec robot %s; restarted it, its hidden state is zero" % problem
                )
        try:
            return json.loads(reply)
        except ValueError:
            raise RuntimeError("macdec robot sent an unreadable reply: %r" % reply[:200])

    def stop(self, kill=False):
        """Close the child's stdin and wait for it (5 s, then kill); with `kill`, kill it at once
        (a child that missed a deadline may never read its stdin again)."""
        if self.child is None:
            return
        if kill and self.child.poll() is None:
            self.child.kill()
        try:
            self.child.stdin.close()
        except OSError:
            pass
        try:
            self.child.wait(timeout=5)
        except subprocess.TimeoutExpired:
            self.child.kill()
            self.child.wait()
        self.child.stdout.close()


class RobotSession:
    """One robot's policy as its node serves it: `macdec robot`'s protocol plus the primitive step.

    A ROS message carries only a macro-observation, but a policy that reads the time (ACAC's
    actors, through their time embedding) needs the primitive step the observation was made at.
    The robot's side publishes one message per primitive step (`macro_action_done` when its
    macro-action finished, and the first of an episode; `macro_obs` otherwise), so that step is
    the number of observations the policy accepted since the last reset: counted here and sent
    as `"step"` with every observation, exactly what `macdec deploy` sends from the
    environment's clock (policies that do not read the time ignore it). Only accepted
    observations count: a refused one (wrong length, non-finite values) leaves the count
    unchanged, as it leaves the policy's hidden state, and so does a request that got no reply;
    a reset starts the count again."""

    def __init__(self, policy):
        self.policy = policy
        self.step = 0

    def info(self, restart=True):
        return self.policy.request({"type": "info"}, restart=restart)

    def observe(self, obs, macro_action_done):
        """The reply to one observation (a dict; RuntimeError as `PolicyProcess.request`)."""
        message = {
            "type": "observe",
            "obs": obs,
            "macro_action_done": macro_action_done,
            "step": self.step,
        }
        reply = self.policy.request(message)
        if "error" not in reply:
            self.step += 1
        return reply

    def reset(self):
        """Zero the policy's hidden state and the step count (a new episode)."""
        reply = self.policy.request({"type": "reset"})
        if "error" not in reply:
            self.step = 0
        return reply


def manifest_path(policy_dir):
    """policy.json since format_version 2; manifest.json in exports written before."""
    name = "policy.json" if os.path.lexists(os.path.join(policy_dir, "policy.json")) else "manifest.json"
    return os.path.join(policy_dir, name)


def read_manifest(policy_dir, max_bytes=MAX_MANIFEST_BYTES):
    """The parsed policy.json (or manifest.json) of `policy_dir`. Refused with a ValueError naming
    the file: a link, FIFO, device or directory (checked before reading, without blocking), a file
    larger than `max_bytes`, unreadable JSON, or no "agents" list."""
    path = manifest_path(policy_dir)
    flags = os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)
    try:
        fd = os.open(path, flags)
    except OSError as e:
        raise ValueError("%s: %s" % (path, e.strerror or e))
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            raise ValueError("%s: not a regular file" % path)
        if info.st_size > max_bytes:
            raise ValueError("%s: %d bytes, more than %d" % (path, info.st_size, max_bytes))
    except BaseException:
        os.close(fd)
        raise
    with os.fdopen(fd, "rb") as f:
        data = f.read(max_bytes + 1)
    if len(data) > max_bytes:
        raise ValueError("%s: grew past %d bytes while being read" % (path, max_bytes))
    try:
        manifest = json.loads(data)
        agents = manifest["agents"]
        if not isinstance(agents, list):
            raise TypeError("not a list")
    except (ValueError, KeyError, TypeError) as e:
        raise ValueError("%s: not a policy manifest with an agents list: %s" % (path, e))
    return manifest


def _tcp_hex(address):
    """`(ip, port)` as /proc/net/tcp writes an IPv4 address: little-endian hex IP, hex port."""
    ip, port = address[:2]
    packed = bytes(int(part) for part in ip.split("."))
    return "%08X:%04X" % (int.from_bytes(packed, "little"), port)


def socket_inode(local, remote, table="/proc/net/tcp"):
    """The inode of the IPv4 TCP socket whose local end is `local` and remote end `remote`
    (`(ip, port)` pairs), or None."""
    want = (_tcp_hex(local), _tcp_hex(remote))
    with open(table) as f:
        next(f)
        for row in f:
            fields = row.split()
            if (fields[1], fields[2]) == want:
                return fields[9]
    return None


def process_tree(pid):
    """`pid` and every process below it (Linux /proc), so a `--macdec` wrapper script that starts
    macdec as its child, rather than exec'ing it, is still the process this node started."""
    parents = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open("/proc/%s/stat" % entry) as f:
                # "pid (comm) state ppid ...": comm may hold spaces and parentheses.
                parents[int(entry)] = int(f.read().rsplit(")", 1)[1].split()[1])
        except (OSError, IndexError, ValueError):
            continue
    tree, grew = {pid}, True
    while grew:
        below = {child for child, parent in parents.items() if parent in tree} - tree
        tree |= below
        grew = bool(below)
    return tree


def owns_connection(pid, conn):
    """Whether process `pid` (or a process below it) holds the other end of `conn`, an accepted
    loopback IPv4 TCP connection (Linux: the peer socket's inode is among /proc/PID/fd). False
    when it cannot tell."""
    try:
        peer, ours = conn.getpeername(), conn.getsockname()
        inode = socket_inode(peer, ours)
        if inode is None or inode == "0":
            return False
        target = "socket:[%s]" % inode
        for owner in sorted(process_tree(pid)):
            fd_dir = "/proc/%d/fd" % owner
            try:
                fds = os.listdir(fd_dir)
            except OSError:
                continue
            for fd in fds:
                try:
                    if os.readlink(os.path.join(fd_dir, fd)) == target:
                        return True
                except OSError:
                    continue
    except (OSError, ValueError, StopIteration):
        return False
    return False
