#!/usr/bin/python3
"""Starts every deployment file's server command line with the built binaries
and serves a scene through it over TLS with a bearer token (CTest
deploy_start_test; docs/deployment.md).

For each of deploy/Dockerfile (ENTRYPOINT + CMD), deploy/compose.yaml (each
server's `command` after the image's ENTRYPOINT; the `secrets` service's
command makes the CA and tokens), deploy/kubernetes/server-deployment.yaml
(the container's args, $(VAR) from the Secrets' example values) and
deploy/systemd/cablesim-server.service (ExecStart, ${VAR} from Environment=
and an EnvironmentFile setting CABLESIM_LISTEN=0.0.0.0:50051, %d the
credentials directory):

- the command runs as written, in a network namespace of its own (so
  0.0.0.0:50051 is reachable only inside it) and a private mount namespace
  where the paths the file names (/run/secrets/cablesim, /var/lib/cablesim,
  /usr/local/bin, /etc/hosts) are the test's: the built build/bin binaries,
  secrets made with the openssl command line, a PostgreSQL started here
  (initdb, pg_ctl) under the host name the file gives, as the unprivileged
  user the file names;
- the file's health checks (Docker HEALTHCHECK, compose healthcheck, the
  Kubernetes probes' exec commands) must report SERVING;
- `cablesim run SCENE --server localhost:50051 --tls-ca CA --token-file T`
  must succeed, and the same without the token must be refused;
- where the file turns the metrics endpoint on (--metrics-listen),
  GET /metrics must answer;
- SIGTERM must stop the server with exit status 0;
- the systemd server runs under strace: every system call it makes must be
  allowed by the unit's SystemCallFilter (expanded by systemd-analyze
  syscall-filter), setpriority among them.

Needs root (network and mount namespaces); skipped (exit 77) otherwise, or
without ip, unshare, openssl or PostgreSQL's initdb.

Usage: deploy_start_test.py SOURCE_DIR BIN_DIR
"""
import glob
import json
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile
import time

import yaml

SOURCE, BIN = (os.path.abspath(a) for a in sys.argv[1:3])
DEPLOY = os.path.join(SOURCE, "deploy")
SCENE = os.path.join(SOURCE, "scenes", "falling-pendulum.json")
SECRETS = "/run/secrets/cablesim"  # where every deployment file reads them
FAILURES = []


def skip(why):
    print(f"SKIPPED: {why}")
    sys.exit(77)


def check(condition, message):
    print(("ok   " if condition else "FAIL ") + message)
    if not condition:
        FAILURES.append(message)
    return condition


def run(argv, **kw):
    return subprocess.run(argv, capture_output=True, text=True, timeout=120, **kw)


# ---- the deployment files' command lines --------------------------------


def dockerfile():
    """ENTRYPOINT, CMD, the HEALTHCHECK's command and the USER."""
    text = open(os.path.join(DEPLOY, "Dockerfile")).read().replace("\\\n", " ")
    found = {}
    for line in text.split("\n"):
        m = re.match(r"^(ENTRYPOINT|CMD|USER|HEALTHCHECK)\s+(.*)$", line.strip())
        if m:
            found[m.group(1)] = m.group(2)
    health = json.loads(re.search(r"CMD\s+(\[.*\])", found["HEALTHCHECK"]).group(1))
    return {
        "entrypoint": json.loads(found["ENTRYPOINT"]),
        "cmd": json.loads(found["CMD"]),
        "health": health,
        "user": found["USER"].split(":")[0],
    }


def compose():
    return yaml.safe_load(open(os.path.join(DEPLOY, "compose.yaml")))


def kubernetes_objects():
    objects = []
    for f in sorted(glob.glob(os.path.join(DEPLOY, "kubernetes", "*.yaml"))):
        objects += [o for o in yaml.safe_load_all(open(f)) if o]
    return objects


def systemd_unit():
    """The [Service] section's assignments, in order: [(key, value)]."""
    items, section = [], None
    for line in open(os.path.join(DEPLOY, "systemd", "cablesim-server.service")):
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        if line.startswith("["):
            section = line
            continue
        if section == "[Service]":
            key, _, value = line.partition("=")
            items.append((key, value))
    return items


# ---- namespaces ----------------------------------------------------------


class Namespace:
    """A network namespace with loopback up, torn down at the end."""

    def __init__(self, name):
        self.name = name
        subprocess.run(["ip", "netns", "delete", name], capture_output=True)
        subprocess.run(["ip", "netns", "add", name], check=True)
        subprocess.run(["ip", "netns", "exec", name, "ip", "link", "set", "lo", "up"], check=True)

    def argv(self, argv, mounts=(), user=None, env=None):
        """argv run in this namespace, in a private mount namespace where
        each (source, target) of mounts is bound (targets under /run and
        /var/lib on fresh tmpfs), as user (uid) when given."""
        script = ["set -e", "mount -t tmpfs -o mode=0755 tmpfs /run",
                  "mount -t tmpfs -o mode=0755 tmpfs /var/lib"]
        for source, target in mounts:
            if os.path.isdir(source):
                script.append(f"mkdir -p {shlex.quote(target)}")
            script.append(f"mount --bind {shlex.quote(source)} {shlex.quote(target)}")
        prefix = []
        if user is not None:
            prefix = ["setpriv", f"--reuid={user}", f"--regid={user}", "--clear-groups",
                      "--inh-caps=-all", "--bounding-set=-all"]
        script.append('exec "$@"')
        full = ["ip", "netns", "exec", self.name, "unshare", "--mount", "--propagation", "private",
                "sh", "-c", "\n".join(script), "sh"] + prefix + list(argv)
        if env is not None:
            full = ["env", "-i"] + [f"{k}={v}" for k, v in env.items()] + full
        return full

    def close(self):
        subprocess.run(["ip", "netns", "delete", self.name], capture_output=True)


class Postgres:
    """PostgreSQL on 127.0.0.1:5432 inside a namespace, with a role and a
    database, both `cablesim` (trust authentication: PGPASSWORD is ignored)."""

    def __init__(self, ns, tmp):
        bindir = max(glob.glob("/usr/lib/postgresql/*/bin"))
        self.ns, self.bindir = ns, bindir
        self.dir = os.path.join(tmp, "pg")
        os.makedirs(self.dir)
        shutil.chown(self.dir, "postgres", "postgres")
        as_pg = ["runuser", "-u", "postgres", "--"]
        r = run(as_pg + [f"{bindir}/initdb", "-D", f"{self.dir}/data", "-A", "trust", "-U", "postgres"])
        if r.returncode != 0:
            raise RuntimeError("initdb: " + r.stderr)
        r = run(["ip", "netns", "exec", ns.name] + as_pg + [
            f"{bindir}/pg_ctl", "-D", f"{self.dir}/data", "-l", f"{self.dir}/log", "-w", "-o",
            f"-c listen_addresses=127.0.0.1 -c port=5432 -k {self.dir} -c fsync=off", "start"])
        if r.returncode != 0:
            raise RuntimeError("pg_ctl start: " + r.stdout + r.stderr + open(f"{self.dir}/log").read())
        for argv in (["createuser", "-h", "127.0.0.1", "-U", "postgres", "cablesim"],
                     ["createdb", "-h", "127.0.0.1", "-U", "postgres", "-O", "cablesim", "cablesim"]):
            r = run(["ip", "netns", "exec", ns.name] + as_pg + [f"{bindir}/{argv[0]}"] + argv[1:])
            if r.returncode != 0:
                raise RuntimeError(" ".join(argv) + ": " + r.stderr)

    def close(self):
        run(["ip", "netns", "exec", self.ns.name, "runuser", "-u", "postgres", "--",
             f"{self.bindir}/pg_ctl", "-D", f"{self.dir}/data", "-m", "immediate", "stop"])


# ---- one deployment -------------------------------------------------------


def make_secrets(directory, owner):
    """A CA, a server certificate for localhost and 127.0.0.1, and a token
    file, with the openssl command line (independently of make-secrets.sh)."""
    os.makedirs(directory)
    d = directory
    steps = [
        ["openssl", "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-days", "2", "-subj",
         "/CN=test CA", "-keyout", f"{d}/ca.key", "-out", f"{d}/ca.crt"],
        ["openssl", "req", "-newkey", "rsa:2048", "-nodes", "-subj", "/CN=localhost",
         "-keyout", f"{d}/tls.key", "-out", f"{d}/tls.csr"],
        ["openssl", "x509", "-req", "-in", f"{d}/tls.csr", "-CA", f"{d}/ca.crt", "-CAkey",
         f"{d}/ca.key", "-CAcreateserial", "-days", "2", "-extfile", f"{d}/ext", "-out",
         f"{d}/tls.crt"],
    ]
    with open(f"{d}/ext", "w") as f:
        f.write("subjectAltName=DNS:localhost,IP:127.0.0.1\n")
    for argv in steps:
        r = run(argv)
        if r.returncode != 0:
            raise RuntimeError(" ".join(argv) + ": " + r.stderr)
    token = run(["openssl", "rand", "-hex", "32"]).stdout.strip()
    with open(f"{d}/tokens", "w") as f:
        f.write(f"# TOKEN TENANT\n{token} deploy-test\n")
    for name in ("tls.key", "tokens", "tls.crt", "ca.crt"):
        os.chown(f"{d}/{name}", owner, owner)
        os.chmod(f"{d}/{name}", 0o400 if name in ("tls.key", "tokens") else 0o444)


def serve_and_check(name, ns, argv, mounts, user, env, health_commands, ca, tokens,
                    strace_out=None):
    """Starts argv, runs the health commands, a scene with and without the
    token, stops it; True when all of it went as expected."""
    if strace_out:
        argv = ["strace", "-f", "-qq", "-o", strace_out, "--"] + argv
    server = subprocess.Popen(ns.argv(argv, mounts, user, env), stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True)
    health_argv = lambda cmd: ns.argv(cmd, mounts, user, {"PATH": "/usr/local/bin:/usr/bin:/bin"})
    serving = False
    deadline = time.time() + 30
    while time.time() < deadline and server.poll() is None:
        r = run(health_argv(health_commands[0]))
        if r.returncode == 0 and '"SERVING"' in r.stdout:
            serving = True
            break
        time.sleep(0.2)
    ok = check(serving, f"{name}: `{' '.join(argv[-len(argv):])}` starts and its health check "
                        f"reports SERVING")
    if serving:
        for cmd in health_commands[1:]:
            r = run(health_argv(cmd))
            ok &= check(r.returncode == 0 and '"SERVING"' in r.stdout,
                        f"{name}: health check `{' '.join(cmd)}`: {r.stdout.strip()}{r.stderr.strip()}")
        out = tempfile.mktemp(suffix=".csv")
        client = [os.path.join(BIN, "cablesim"), "run", SCENE, "--server", "localhost:50051",
                  "--tls-ca", ca, "--out", out]
        r = run(["ip", "netns", "exec", ns.name] + client + ["--token-file", tokens])
        summary = r.stdout.strip().splitlines()[-1] if r.stdout.strip() else ""
        ok &= check(r.returncode == 0 and '"status":"ok"' in summary and os.path.getsize(out) > 0,
                    f"{name}: a scene runs through it over TLS with the token (exit {r.returncode}"
                    f"{': ' + r.stderr.strip() if r.returncode else ''})")
        r = run(["ip", "netns", "exec", ns.name] + client)
        ok &= check(r.returncode != 0 and "token" in r.stderr,
                    f"{name}: the same without a token is refused (exit {r.returncode})")
        for flag in (a for a in argv if a.startswith("--metrics-listen=")):
            port = flag.rsplit(":", 1)[1]
            r = run(["ip", "netns", "exec", ns.name, "curl", "-s", f"http://127.0.0.1:{port}/metrics"])
            ok &= check(r.returncode == 0 and "\ncablesim_jobs_queued 0\n" in r.stdout
                        and 'cablesim_jobs_finished_total{state="SUCCEEDED"}' in r.stdout,
                        f"{name}: GET /metrics on port {port} answers (exit {r.returncode})")
        if os.path.exists(out):
            os.remove(out)
    if server.poll() is None:
        # SIGTERM to the server itself: the namespace wrappers exec into it,
        # strace forks it.
        pid = server.pid
        if strace_out:
            with open(f"/proc/{pid}/task/{pid}/children") as f:
                pid = int(f.read().split()[0])
        os.kill(pid, signal.SIGTERM)
    try:
        log, _ = server.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        server.kill()
        log, _ = server.communicate()
    ok &= check(server.returncode == 0, f"{name}: SIGTERM stops it with exit 0 "
                                        f"(exit {server.returncode})")
    if not ok:
        print(f"---- {name}: server output\n{log}----")
    return ok


def main():
    if os.geteuid() != 0:
        skip("starting the deployments needs root (network and mount namespaces); "
             "run as root, as CI does")
    for tool in ("ip", "unshare", "openssl", "setpriv", "strace", "runuser", "curl"):
        if shutil.which(tool) is None:
            skip(f"no {tool} (deploy/install-deps.sh installs it)")
    if not glob.glob("/usr/lib/postgresql/*/bin/initdb"):
        skip("PostgreSQL is not installed (deploy/install-deps.sh installs it)")

    tmp = tempfile.mkdtemp(prefix="cablesim-deploy-")
    os.chmod(tmp, 0o755)
    ns = Namespace(f"cablesim-deploy-{os.getpid()}")
    postgres = None
    try:
        uid = 10001
        secrets = os.path.join(tmp, "secrets")
        make_secrets(secrets, uid)
        ca, tokens = f"{secrets}/ca.crt", f"{secrets}/tokens"
        data = os.path.join(tmp, "data")
        os.makedirs(data)
        os.chown(data, uid, uid)
        os.chmod(data, 0o700)
        bin_mount = (BIN, "/usr/local/bin")
        env = {"PATH": "/usr/local/bin:/usr/bin:/bin", "HOME": "/var/lib/cablesim"}

        # Docker: ENTRYPOINT + CMD as USER, the HEALTHCHECK.
        d = dockerfile()
        check(d["user"] == str(uid), f"Dockerfile: USER {d['user']}")
        serve_and_check("Dockerfile", ns, d["entrypoint"] + d["cmd"],
                        [bin_mount, (secrets, SECRETS), (data, "/var/lib/cablesim")], uid, env,
                        [d["health"]], ca, tokens)

        # PostgreSQL for compose and Kubernetes, under the host names they give.
        postgres = Postgres(ns, tmp)
        hosts = os.path.join(tmp, "hosts")

        # compose: the secrets service's command (make-secrets.sh) as the
        # image would run it, then each server's command.
        c = compose()
        init = c["services"]["secrets"]
        made = os.path.join(tmp, "compose-secrets")
        os.makedirs(made)
        volume = next(v for v in init["volumes"])
        init_target = volume.split(":")[1]
        init_env = dict(env, **{k: str(v) for k, v in init.get("environment", {}).items()})
        r = run(ns.argv(init["entrypoint"] + init["command"],
                        # The image's copy of make-secrets.sh (Dockerfile COPY).
                        [(DEPLOY, "/usr/local/share/cablesim"), (made, init_target)],
                        None, init_env))
        check(r.returncode == 0 and os.path.exists(f"{made}/tls.crt"),
              f"compose: secrets: `{' '.join(init['entrypoint'] + init['command'])}` "
              f"makes the CA and tokens ({r.stdout.strip()}{r.stderr.strip()})")
        servers = {n: s for n, s in c["services"].items() if any(
            a.startswith("--listen") for a in s.get("command", []))}
        check(len(servers) == 2, f"compose: two servers ({', '.join(servers)})")
        for name, s in servers.items():
            store = next(a for a in s["command"] if a.startswith("--store="))
            host = re.match(r"--store=postgresql://[^@]+@([^:/]+)", store).group(1)
            with open(hosts, "w") as f:
                f.write(f"127.0.0.1 localhost {host}\n")
            mounts = [bin_mount, (hosts, "/etc/hosts")]
            for v in s["volumes"]:
                source, target = v.split(":")[:2]
                mounts.append((os.path.normpath(os.path.join(DEPLOY, source)).replace(
                    os.path.join(DEPLOY, "cablesim-secrets"), made), target))
            senv = dict(env, PGPASSWORD="ignored-by-trust-auth")
            serve_and_check(f"compose {name}", ns, d["entrypoint"] + s["command"], mounts, uid,
                            senv, [s["healthcheck"]["test"][1:]], f"{made}/ca.crt",
                            f"{made}/tokens")

        # Kubernetes: the Deployment's container args after the image's
        # ENTRYPOINT, $(VAR) from the Secrets, the Secret volumes mounted.
        objects = kubernetes_objects()
        deployment = next(o for o in objects if o["kind"] == "Deployment")
        secrets_by_name = {o["metadata"]["name"]: o for o in objects if o["kind"] == "Secret"}
        pod = deployment["spec"]["template"]["spec"]
        for container in pod["containers"]:
            values = {}
            for e in container.get("env", []):
                ref = e.get("valueFrom", {}).get("secretKeyRef")
                values[e["name"]] = (secrets_by_name[ref["name"]]["stringData"][ref["key"]]
                                     if ref else e.get("value", ""))
            expand = lambda a: re.sub(r"\$\((\w+)\)", lambda m: values[m.group(1)], a)
            argv = (container.get("command") or d["entrypoint"]) + [expand(a) for a in container["args"]]
            store = next(a for a in argv if a.startswith("--store="))
            host = re.match(r"--store=postgresql://[^@]+@([^:/]+)", store).group(1)
            with open(hosts, "w") as f:
                f.write(f"127.0.0.1 localhost {host}\n")
            volumes = {v["name"]: v for v in pod["volumes"]}
            mounts = [bin_mount, (hosts, "/etc/hosts")]
            for m in container["volumeMounts"]:
                v = volumes[m["name"]]
                if "projected" in v or "secret" in v:
                    mounts.append((secrets, m["mountPath"]))
            cenv = dict(env, **{k: v for k, v in values.items()})
            probes = [container[p]["exec"]["command"]
                      for p in ("startupProbe", "readinessProbe", "livenessProbe") if p in container]
            check(len(probes) == 3, f"kubernetes: {container['name']}: startup, readiness and "
                                    f"liveness probes run commands")
            serve_and_check(f"kubernetes {container['name']}", ns, argv, mounts,
                            pod["securityContext"]["runAsUser"], cenv, probes, ca, tokens)

        # systemd: ExecStart with ${VAR} from Environment= and an
        # EnvironmentFile listening beyond loopback, %d the credentials.
        unit = systemd_unit()
        variables = {}
        for key, value in unit:
            if key == "Environment":
                k, _, v = value.partition("=")
                variables[k] = v
        variables["CABLESIM_LISTEN"] = "0.0.0.0:50051"  # as /etc/cablesim/server.env may set
        credentials = os.path.join(tmp, "credentials")
        os.makedirs(credentials)
        for key, value in unit:
            if key == "LoadCredential":
                cred, _, path = value.partition(":")
                shutil.copy(os.path.join(secrets, os.path.basename(path)), f"{credentials}/{cred}")
        dynamic_uid = 61999
        for f in os.listdir(credentials):
            os.chown(f"{credentials}/{f}", dynamic_uid, dynamic_uid)
        state_dir = os.path.join(tmp, "state")  # StateDirectory: the dynamic user's, 0700
        os.makedirs(state_dir)
        os.chown(state_dir, dynamic_uid, dynamic_uid)
        os.chmod(state_dir, 0o700)
        exec_start = next(v for k, v in unit if k == "ExecStart")
        exec_start = exec_start.replace("%d", "/run/credentials/cablesim-server.service")
        exec_start = re.sub(r"\$\{(\w+)\}", lambda m: variables[m.group(1)], exec_start)
        argv = shlex.split(exec_start)
        trace = os.path.join(tmp, "strace")
        open(trace, "w").close()
        os.chown(trace, dynamic_uid, dynamic_uid)
        state = next(v for k, v in unit if k == "StateDirectory")
        serve_and_check("systemd", ns, argv,
                        [bin_mount, (credentials, "/run/credentials/cablesim-server.service"),
                         (state_dir, f"/var/lib/{state}")],
                        dynamic_uid, {"PATH": "/usr/bin:/bin"},
                        [["cablesim", "health", "--server", "localhost:50051", "--tls-ca", ca]],
                        ca, tokens, strace_out=trace)
        check_syscalls(unit, trace)
    finally:
        if postgres:
            postgres.close()
        ns.close()
        shutil.rmtree(tmp, ignore_errors=True)
    print(f"{len(FAILURES)} failed")
    sys.exit(1 if FAILURES else 0)


def check_syscalls(unit, trace):
    """Every system call in strace's log must be in the unit's filter."""

    def expand(names):
        out = set()
        for n in names:
            if n.startswith("@"):
                r = run(["systemd-analyze", "syscall-filter", n])
                out |= {l.strip() for l in r.stdout.splitlines()[1:]
                        if l.strip() and not l.strip().startswith(("#", "@"))}
                out |= expand([l.strip() for l in r.stdout.splitlines()[1:]
                               if l.strip().startswith("@")])
            else:
                out.add(n)
        return out

    allowed = None
    for key, value in unit:
        if key != "SystemCallFilter":
            continue
        deny = value.startswith("~")
        names = expand(value.lstrip("~").split())
        if allowed is None:
            allowed = set() if not deny else None
        if allowed is None:
            break  # a deny list: not what this unit uses
        allowed = allowed - names if deny else allowed | names
    if not check(allowed is not None, "systemd: SystemCallFilter is an allow list"):
        return
    used = set()
    for line in open(trace):
        m = re.match(r"^\d+\s+([a-z0-9_]+)\(", line)
        if m:
            used.add(m.group(1))
    # The wrappers' own calls (setpriv, sh) come before execve of the server.
    check("setpriority" in allowed, "systemd: the filter allows setpriority")
    check("setpriority" in used, "systemd: the server calls setpriority (its workers' priority)")
    denied = sorted(used - allowed)
    check(not denied, f"systemd: every system call the server made is allowed by the unit's "
                      f"SystemCallFilter ({len(used)} distinct; denied: {denied})")


if __name__ == "__main__":
    main()
