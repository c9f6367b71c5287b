"""The grading sandbox: a student's solution cells, run behind a fence they cannot switch off.

``judge`` starts it as ``python -I -m geomlib.teaching.check.sandbox`` (isolated: no
current folder, no user site, no PYTHON* variables). This first process, the *zygote*, runs
the import statements the judge hands it (``load``: the solution notebook's, those binding a
name its solution cells or ``use`` cells read, not its plotting) in a namespace it throws
away, and nothing else: it never runs the student's code, nor the student's imports. For each
exercise the judge writes a plan (the student's import statements, the solution cells, the
geomlib routines the exercise allows and the names the ``use`` cells bind now) and the zygote
forks a fresh process for it: that process starts from the state a new interpreter has after
the lecturer's imports (paid once per grading run, not once per exercise), runs the student's
import statements in a fresh namespace (the modules already loaded: cheap), *arms*, and only
then runs the solution cells. A fork copies the zygote's memory, so nothing a process does
reaches the zygote or the processes forked after it. From arming on, for good:

* the fence's profile (``fence.Fence.profile``) watches every call; an entry into fenced
  code (geomlib outside the allow-list, a geometry library) ends the process;
* libigl's compiled routines are tripwires; geomlib's caches are empty;
* an audit hook (``sys.addaudithook``: it cannot be removed) ends the process on
  ``sys.setprofile``/``sys.settrace`` (which would switch the profile off), a process
  (fork, spawn, subprocess), ctypes, a new code object, a rewritten function, a file
  opened for writing, the garbage collector's object lists, an import of a geometry
  library, and compiling or executing code other than the solution cells and real
  module files (sympy's lambdify and the standard library's namedtuple and dataclass
  makers aside);
* starting a thread ends the process (``_thread.start_new_thread`` is a tripwire).

"Ends the process" is ``os._exit(3)`` after writing ``{"hit": name, "why": what}`` to the
reply channel, from a function holding every name it uses as a default argument, so
nothing the student's code rebinds can stop it. The judge reads the exit status too:
status 3 is a refusal even when the frame is lost.

Then the sandbox answers ``{"call": name, "args": [...]}`` with ``{"ok": value, "args":
[...after the call]}`` or ``{"raised": type, "message": ..., "stub": bool}``, and ``{"bye":
true}`` by exiting with status 0. The zygote says ``{"forked": pid}`` and, once that process
has ended, ``{"ended": status}``, so the judge reads its exit status as it would a process of
its own; ``bye!`` (or its socket closed) ends the zygote. Student prints go to /dev/null;
requests come on the process's stdin, replies go to a pipe of its own.
"""

import ast
import importlib
import os
import socket
import sys

from .wire import decode, encode, receive, send

HIT_STATUS = 3


def import_statements(sources, names):
    """The import statements of a notebook's cells (``sources``) that bind one of ``names`` (magics
    and everything else left out): what the solution cells use, without the notebook's plotting."""
    kept = []
    for source in sources:
        lines = [line for line in source.splitlines() if not line.lstrip().startswith(("%", "!"))]
        try:
            tree = ast.parse("\n".join(lines))
        except SyntaxError:
            continue
        for node in tree.body:
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                node.names = [a for a in node.names if (a.asname or a.name).partition(".")[0] in names]
                if node.names:
                    kept.append(ast.unparse(node))
    return "\n".join(kept)


def names_used(sources):
    """Every name the solution cells read (a superset of what they need from the imports)."""
    found = set()
    for source in sources:
        try:
            found |= {n.id for n in ast.walk(ast.parse(source)) if isinstance(n, ast.Name)}
        except SyntaxError:
            continue
    return found


def _library_dirs():
    """Folders whose module files may be imported and run while armed: the standard library, the
    installed packages (a geometry library's import is refused before it runs) and geomlib, whose
    routines the profile fences. The student's code can write no file there while armed."""
    import sysconfig

    paths = sysconfig.get_paths()
    dirs = {os.path.realpath(paths[key]) for key in ("stdlib", "platstdlib", "purelib", "platlib")}
    dirs.update(os.path.realpath(d) for d in importlib.util.find_spec("geomlib").submodule_search_locations)
    return tuple(os.path.join(d, "") for d in dirs)


def _makers():
    """Files whose code may compile and run code while armed: sympy (lambdify), mpmath, namedtuple,
    dataclasses, and ``ast.parse`` (a syntax tree only: running it takes a compile of its own)."""
    import ast
    import collections
    import dataclasses

    found = [ast.__file__, collections.__file__, dataclasses.__file__]
    for name in ("sympy", "mpmath"):  # lambdify; mpmath's number context makes its functions at first use
        spec = importlib.util.find_spec(name)
        if spec is not None and spec.submodule_search_locations:
            found += [os.path.join(os.path.realpath(d), "") for d in spec.submodule_search_locations]
    return tuple(found)


def _fatal_function(reply):
    def fatal(name, why="", reply=reply, send=send, exit=os._exit, status=HIT_STATUS):
        try:
            send(reply, {"hit": name, "why": why})
        finally:
            exit(status)

    return fatal


def _audit_hook(fatal, cells, libraries, makers, geometry):
    """The sandbox's audit hook (module docstring); every name it uses is a default argument."""
    import io

    def hook(
        event,
        args,
        fatal=fatal,
        cells=cells,
        libraries=libraries,
        makers=makers,
        geometry=geometry,
        getframe=sys._getframe,
        isfile=os.path.isfile,
        opener=io.open,
        isinstance=isinstance,
        str=str,
        bytes=bytes,
        writing=os.O_WRONLY | os.O_RDWR | os.O_CREAT | os.O_APPEND | os.O_TRUNC,
        importer=("<frozen importlib", importlib._bootstrap.__file__, importlib._bootstrap_external.__file__),
        processes=("os.fork", "os.forkpty", "os.posix_spawn", "os.spawn", "os.exec", "os.system", "subprocess.Popen"),
        setters=("__code__", "__defaults__", "__kwdefaults__", "__closure__"),
    ):
        if event == "import":
            if args[0].partition(".")[0] in geometry:
                fatal(f"the geometry library `{args[0]}`", f"imports {args[0]}, a geometry library")
            return
        if event in ("sys.setprofile", "sys.settrace"):
            fatal(event, f"calls {event}, which would switch the grading's watcher off")
        if event in processes:
            fatal(event, "starts a process")
        if event.startswith(("ctypes.", "gc.get_")) or event in ("code.__new__", "marshal.dumps"):
            fatal(event, f"uses {event}")
        if event == "object.__setattr__" and args[1] in setters:
            fatal(event, f"rewrites a function's {args[1]}")
        if event == "open":
            mode, flags = args[1], args[2]
            if (mode is not None and ("w" in mode or "a" in mode or "x" in mode or "+" in mode)) or (
                mode is None and flags & writing
            ):
                fatal(event, f"opens {args[0]} for writing")
            return
        if event not in ("compile", "exec", "marshal.loads"):
            return
        if event == "exec" and args[0] in cells:
            return
        caller = getframe(1)
        where = "" if caller is None else caller.f_code.co_filename
        if where.startswith(makers):
            return
        if where.startswith(importer[0]) or where in importer[1:]:  # the import system, loading a module file
            if event == "marshal.loads" or (event == "compile" and args[1] == "<internal>"):
                return  # a compiled module's own start-up code (Cython's), which no Python exec can run
            path = args[1] if event == "compile" else args[0].co_filename
            if isinstance(path, str) and path.startswith(libraries) and isfile(path):
                if event == "exec":
                    return
                source = args[0].encode() if isinstance(args[0], str) else args[0]
                if isinstance(source, bytes):
                    with opener(path, "rb") as f:
                        if f.read() == source:
                            return
        fatal(event, f"runs {event} on code of its own while it is graded ({where or '?'})")

    return hook


def _arm(ns, allow, fatal, cells):
    """Put the fence up for good (module docstring)."""
    import _imp
    import _thread
    import threading

    from .fence import GEOMETRY_LIBRARIES, Fence, cold_caches

    fence = Fence(allow)

    def no_thread(*args, fatal=fatal):
        fatal("a thread", "starts a thread (grading watches the one it calls the function in)")

    def no_builtin(spec, fatal=fatal, create=_imp.create_builtin):
        if spec.name in ("_thread", "_imp", "sys", "builtins"):
            fatal("a fresh builtin module", f"makes a fresh {spec.name} module")
        return create(spec)

    def same_filename(code, path, fatal=fatal, fix=_imp._fix_co_filename):
        if code.co_filename != path:
            fatal("a renamed code object", "renames a code object's file")
        return fix(code, path)

    _thread.start_new_thread = threading._start_new_thread = no_thread
    _imp.create_builtin, _imp._fix_co_filename = no_builtin, same_filename
    cold_caches()
    fence.tripwires([ns], lambda name, fatal=fatal: fatal(name))
    hook = _audit_hook(fatal, frozenset(cells), _library_dirs(), _makers(), frozenset(GEOMETRY_LIBRARIES))
    profile = fence.profile(fatal)
    sys.dont_write_bytecode = True
    sys.setprofile(profile)
    sys.addaudithook(hook)


def _reference(ns, dotted):
    """A name, or a dotted attribute of one, in the notebook's namespace (no evaluation)."""
    head, *rest = dotted.split(".")
    value = ns[head]
    for part in rest:
        value = getattr(value, part)
    return value


def main():
    zygote(socket.socket(fileno=int(sys.argv[1])))


def preload(statements):
    """Run import ``statements`` in a namespace thrown away: their modules are then loaded (a statement that
    fails is left to the sandbox's own import statements, which report it)."""
    for statement in statements:
        try:
            exec(compile(statement, "<the imports a sandbox starts with>", "exec"), {"__name__": "__main__"})
        except Exception:  # noqa: BLE001 - the sandbox running the same statement says what failed
            pass


def zygote(control):
    """Fork a fresh sandbox for each exercise (module docstring); never returns.

    On the ``control`` socket, ``load`` and a frame ``{"imports": [statement, ...]}`` import modules
    for the sandboxes forked after; each ``fork`` brings the new process's two pipe ends (its stdin,
    its replies): the process keeps only those, closes the socket and serves the exercise. The
    zygote says ``{"forked": pid}`` and, once the process has ended, ``{"ended": status}``. Anything
    else (``bye!``, the socket closed) ends it."""
    while True:
        word, fds, _, _ = socket.recv_fds(control, 4, 2)
        if word == b"load" and not fds:
            order = receive(control.fileno())
            if order is None:
                os._exit(0)
            preload(order["imports"])
            continue
        if word != b"fork" or len(fds) != 2:
            os._exit(0)
        child = os.fork()
        if child == 0:
            try:
                control.close()
                os.dup2(fds[0], 0)
                os.close(fds[0])
                run(receive(0), fds[1])
            finally:
                os._exit(1)  # run ends the process itself; never back into this loop
        for fd in fds:
            os.close(fd)
        send(control.fileno(), {"forked": child})
        send(control.fileno(), {"ended": os.waitstatus_to_exitcode(os.waitpid(child, 0)[1])})


def run(plan, reply):
    """Run the notebook's import statements in a fresh namespace, compile the solution cells, arm, run
    them, bind the ``use`` names, and serve; never returns."""
    fatal = _fatal_function(reply)
    ns = {"__name__": "__main__"}
    try:
        exec(compile(plan["imports"], "<the notebook's imports>", "exec"), ns)
        cells = [compile(source, f"<solution cell {i + 1}>", "exec") for i, source in enumerate(plan["cells"])]
    except BaseException as exc:  # the imports fail or the student's cells do not compile: the judge says so
        send(reply, {"raised": type(exc).__name__, "message": str(exc), "stub": False, "setup": True})
        os._exit(0)
    _arm(ns, plan["allow"], fatal, cells)
    raised = []  # as in a kernel: a cell that raises stops there, and the next cell still runs
    for i, code in enumerate(cells):
        try:
            exec(code, ns)
        except BaseException as exc:  # noqa: BLE001 - the student's cells may raise anything
            raised.append(f"solution cell {i + 1} raised {type(exc).__name__}: {str(exc)[:300]}")
    try:
        for name, (kind, target) in plan["bindings"].items():
            ns[name] = ns[target] if kind == "student" else _reference(ns, target)
    except BaseException as exc:  # noqa: BLE001 - a use cell names a function no cell defined
        send(reply, {"raised": type(exc).__name__, "message": str(exc)[:500], "stub": False, "setup": True})
        os._exit(0)
    send(reply, {"ready": True})
    serve(ns, reply, raised)


def _callback(reply):
    """``index -> function`` calling the judge's function ``index`` (a check's helper handed to the answer)."""

    def make(index):
        def callback(*args):
            send(reply, {"callback": index, "args": [encode(a) for a in args]})
            answer = receive(0)
            if answer is None or "ok" not in answer:
                raise RuntimeError(f"the check's function raised {answer and answer.get('raised')}: {answer}")
            return decode(answer["ok"])

        return callback

    return make


def serve(ns, reply, raised=()):
    """Answer the judge's calls of the student's functions; ``raised`` says which solution cells raised."""
    callback = _callback(reply)
    while True:
        request = receive(0)
        if request is None or "bye" in request:
            os._exit(0)
        args = [decode(a, callback) for a in request["args"]]
        try:
            if request["call"] not in ns:
                why = f" ({'; '.join(raised)}: grading runs them without the lesson's variables)" if raised else ""
                raise NameError(f"the solution cells define no `{request['call']}`{why}")
            out = ns[request["call"]](*args)
            answer = {"ok": encode(out), "args": [encode(a) for a in args]}
        except BaseException as exc:  # noqa: BLE001 - the student's function may raise anything
            answer = {
                "raised": type(exc).__name__,
                "message": str(exc)[:500],
                "stub": isinstance(exc, NotImplementedError),
            }
        send(reply, answer)


if __name__ == "__main__":
    main()
