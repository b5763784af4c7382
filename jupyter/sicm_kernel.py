#!/usr/bin/env python3
"""sicm's Jupyter kernel: ipykernel's wrapper kernel driving `sicm repl --kernel`.

ipykernel (`ipykernel.kernelbase.Kernel`) speaks Jupyter's messaging protocol
(ZeroMQ sockets, signed messages, heartbeats, the execute/complete/shutdown
requests); this file only translates. Each kernel owns one sicm session, a
child process running `sicm repl --kernel`, so definitions live from cell to
cell; the session answers each request with JSON lines
(compiler/driver/jupyter_protocol.hpp says which). Two reader threads turn
the session's stdout (the replies) and stderr (anything sicm says outside
the protocol) into one queue, which the request being served drains, so an
interrupt never lands in the middle of a read.

Interrupts: the session is started in a session (process group) of its own,
so it gets SIGINT only from us, exactly once per interrupt: Jupyter signals
the kernel, ipykernel raises KeyboardInterrupt while a request is served, and
we pass SIGINT on. The session stops the cell with an "Interrupted" error and
lives on. A second interrupt of the same cell (the session did not answer
the first) restarts the session, which loses its definitions, and says so.

The sicm binary is $SICM_BINARY (the kernel spec of `make jupyter` sets it
to the build's absolute path), else `sicm` on PATH.
"""

import json
import os
import queue
import shutil
import signal
import subprocess
import threading

from ipykernel.kernelbase import Kernel

# Characters that end a name, as the REPL's completion sees them.
WORD_BREAKS = set(" \t\n()\"'`,;[]")


def sicm_binary():
    return os.environ.get("SICM_BINARY") or shutil.which("sicm") or "sicm"


class Session:
    """One `sicm repl --kernel` process and the queue of what it writes."""

    def __init__(self):
        # The session writes its plots into a directory of its own, which it
        # removes when its stdin closes, even if this process was killed.
        self.proc = subprocess.Popen(
            [sicm_binary(), "repl", "--kernel"],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
            start_new_session=True)
        self.replies = queue.Queue()
        for stream, kind in ((self.proc.stdout, "reply"), (self.proc.stderr, "stderr")):
            threading.Thread(target=self._pump, args=(stream, kind), daemon=True).start()
        first = self.next_message()
        if first.get("type") != "ready":
            raise RuntimeError(f"sicm did not start: {first}")

    def _pump(self, stream, kind):
        for line in iter(stream.readline, b""):
            text = line.decode("utf-8", errors="replace")
            if kind == "reply":
                self.replies.put(json.loads(text))
            else:
                self.replies.put({"type": "stream", "name": "stderr", "text": text})
        if kind == "reply":
            self.replies.put({"type": "exit"})

    def send(self, verb, text, name=""):
        data = text.encode("utf-8")
        header = f"{verb} {len(data)}" + (f" {name}" if name else "") + "\n"
        self.proc.stdin.write(header.encode() + data)
        self.proc.stdin.flush()

    def next_message(self, timeout=None):
        """The next message; {"type": "exit"} once the process has ended."""
        return self.replies.get(timeout=timeout)

    def interrupt(self):
        if self.proc.poll() is None:
            os.kill(self.proc.pid, signal.SIGINT)

    def close(self):
        try:
            self.proc.stdin.close()
            self.proc.wait(timeout=5)
        except (OSError, subprocess.TimeoutExpired):
            self.proc.kill()
            self.proc.wait()


class SicmKernel(Kernel):
    implementation = "sicm"
    implementation_version = "0.1"
    language_info = {
        "name": "scheme",
        "mimetype": "text/x-scheme",
        "file_extension": ".sicm",
        "codemirror_mode": "scheme",
        "pygments_lexer": "scheme",
    }
    banner = ("sicm: the Scheme of Structure and Interpretation of Classical Mechanics "
              "(scmutils semantics)")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.sicm = Session()

    # ---- execute ---------------------------------------------------------------

    def do_execute(self, code, silent, store_history=True, user_expressions=None,
                   allow_stdin=False):
        try:
            self.sicm.send("execute", code, f"In[{self.execution_count}]")
        except OSError:  # it ended after the last cell
            return self._restart_session("the session had ended")
        error = None
        interrupted = False
        while True:
            try:
                msg = self.sicm.next_message(timeout=0.1)
                kind = msg["type"]
                if kind == "done":
                    break
                if kind == "exit":
                    return self._restart_session("the session ended")
                if kind == "error":
                    error = msg
                if not silent:
                    self._show(msg)
            except queue.Empty:
                continue
            except KeyboardInterrupt:
                if interrupted:  # the session did not answer the first one
                    return self._restart_session("the session did not stop when interrupted")
                interrupted = True
                self.sicm.interrupt()
        if error:
            return self._error_reply(error)
        return {"status": "ok", "execution_count": self.execution_count,
                "payload": [], "user_expressions": {}}

    def _show(self, msg):
        kind = msg["type"]
        if kind == "stream":
            self.send_response(self.iopub_socket, "stream",
                               {"name": msg["name"], "text": msg["text"]})
        elif kind == "result" and msg["last"]:
            self.send_response(self.iopub_socket, "execute_result",
                               {"execution_count": self.execution_count,
                                "data": msg["data"], "metadata": {}})
        elif kind in ("result", "display"):
            self.send_response(self.iopub_socket, "display_data",
                               {"data": msg["data"], "metadata": {}})
        elif kind == "error":
            self.send_response(self.iopub_socket, "error", self._error_content(msg))

    @staticmethod
    def _error_content(msg):
        return {"ename": msg["ename"], "evalue": msg["evalue"], "traceback": msg["traceback"],
                "line": msg["line"], "col": msg["col"]}

    def _error_reply(self, msg):
        reply = self._error_content(msg)
        reply.update(status="error", execution_count=self.execution_count)
        return reply

    def _restart_session(self, why):
        """Replace the session by a new one and fail the cell saying why."""
        proc = self.sicm.proc
        try:
            why += f" (exit status {proc.wait(timeout=1)})"
        except subprocess.TimeoutExpired:  # it lives on, stuck: end it
            proc.kill()
        self.sicm.close()
        self.sicm = Session()
        text = f"{why}; a new session was started: definitions are lost"
        msg = {"ename": "SessionRestarted", "evalue": text, "traceback": [text],
               "line": 0, "col": 0}
        self.send_response(self.iopub_socket, "error", msg)
        return self._error_reply(msg)

    # ---- complete ---------------------------------------------------------------

    def do_complete(self, code, cursor_pos):
        start = cursor_pos
        while start > 0 and code[start - 1] not in WORD_BREAKS:
            start -= 1
        matches = []
        if start < cursor_pos:
            self.sicm.send("complete", code[start:cursor_pos])
            while (msg := self.sicm.next_message(timeout=30))["type"] not in ("done", "exit"):
                if msg["type"] == "matches":
                    matches = msg["matches"]
        return {"status": "ok", "matches": matches, "cursor_start": start,
                "cursor_end": cursor_pos, "metadata": {}}

    def do_is_complete(self, code):
        depth = 0
        in_string = False
        escaped = False
        in_comment = False
        for c in code:  # a rough count: the session's reader has the last word
            if in_comment:
                in_comment = c != "\n"
            elif in_string:
                escaped, in_string = (c == "\\" and not escaped), (c != '"' or escaped)
            elif c == '"':
                in_string = True
            elif c == ";":
                in_comment = True
            elif c == "(":
                depth += 1
            elif c == ")":
                depth -= 1
        return {"status": "incomplete" if depth > 0 or in_string else "complete",
                "indent": "  " * max(depth, 0)}

    def do_shutdown(self, restart):
        self.sicm.close()
        return {"status": "ok", "restart": restart}


if __name__ == "__main__":
    from ipykernel.kernelapp import IPKernelApp

    IPKernelApp.launch_instance(kernel_class=SicmKernel)
