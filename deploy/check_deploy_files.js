// Checks the deployment files (CTest deploy_files_test; deploy/README.md):
//
// - every manifest in deploy/kubernetes/ parses as YAML and validates
//   against the Kubernetes schemas (the npm package kubernetes-models), and
//   what deploy/README.md promises of them holds: gRPC readiness and
//   liveness probes on the server's port, requests and limits, the store URL
//   and password from the Secret, a headless Service and a
//   PodDisruptionBudget selecting the server pods, an Indexed Job whose pod I
//   runs `cablesim sweep --item I`; the Job's command is run here for its
//   last index on the sweep in the ConfigMap (with the build's cablesim), and
//   the index after it must be refused (completions = the sweep's items);
// - deploy/compose.yaml parses (merge keys resolved) into PostgreSQL and two
//   servers on --store postgresql://, with health checks;
// - deploy/Dockerfile: Debian 12 stages, a non-root user, the gRPC health
//   check, COPY sources that exist, apt packages that exist, and runtime
//   packages that provide every shared library the built binaries link.
//
// Usage: node check_deploy_files.js SOURCE_DIR BIN_DIR. Prints one line per
// check and "N passed, M failed"; exits 1 if any failed.
"use strict";

const fs = require("fs");
const os = require("os");
const path = require("path");
const { execFileSync, spawnSync } = require("child_process");
const YAML = require("yaml");

const [sourceDir, binDir] = process.argv.slice(2);
if (!sourceDir || !binDir) {
  console.error("usage: node check_deploy_files.js SOURCE_DIR BIN_DIR");
  process.exit(2);
}
const deployDir = path.join(sourceDir, "deploy");
let passed = 0;
let failed = 0;

function check(name, fn) {
  try {
    fn();
    passed++;
    console.log(`ok   ${name}`);
  } catch (e) {
    failed++;
    console.log(`FAIL ${name}: ${e.message}`);
  }
}

function expect(condition, message) {
  if (!condition) throw new Error(message);
}

function parseYaml(file, options = {}) {
  const text = fs.readFileSync(file, "utf8");
  const docs = YAML.parseAllDocuments(text, options);
  for (const doc of docs) {
    const problems = doc.errors.concat(doc.warnings);
    expect(problems.length === 0, `${file}: ${problems.map((p) => p.message).join("; ")}`);
  }
  return docs.map((d) => d.toJS({ maxAliasCount: 100 })).filter((d) => d != null);
}

// ---- Kubernetes ------------------------------------------------------------

const manifestDir = path.join(deployDir, "kubernetes");
const objects = [];
for (const file of fs.readdirSync(manifestDir).filter((f) => f.endsWith(".yaml")).sort()) {
  check(`kubernetes/${file}: YAML`, () => {
    for (const o of parseYaml(path.join(manifestDir, file))) objects.push({ file, o });
  });
}

// The kubernetes-models class of an object: kubernetes-models/GROUP/VERSION/KIND
// ("v1" for the core group).
function modelClass(apiVersion, kind) {
  const module = require(`kubernetes-models/${apiVersion}/${kind}`);
  expect(module[kind], `kubernetes-models has no ${apiVersion} ${kind}`);
  return module[kind];
}

for (const { file, o } of objects) {
  // cert-manager's Certificate is a custom resource kubernetes-models has no
  // schema for: its shape is checked below.
  if (o.apiVersion === "cert-manager.io/v1") continue;
  check(`kubernetes/${file}: ${o.kind} ${o.metadata && o.metadata.name} against the schema`, () => {
    expect(o.apiVersion && o.kind, "no apiVersion or kind");
    const Model = modelClass(o.apiVersion, o.kind);
    new Model(o).validate();  // throws naming the field
  });
}

function find(kind, name) {
  const hits = objects.filter(({ o }) => o.kind === kind && (!name || o.metadata.name === name));
  expect(hits.length > 0, `no ${kind}${name ? " " + name : ""} in deploy/kubernetes`);
  return hits.map((h) => h.o);
}

function selects(selector, labels) {
  const want = selector.matchLabels || selector;
  return Object.keys(want).length > 0 && Object.entries(want).every(([k, v]) => labels[k] === v);
}

check("kubernetes: the server Deployment's probes, resources and Secret", () => {
  const [deployment] = find("Deployment", "cablesim-server");
  const pod = deployment.spec.template;
  expect(selects(deployment.spec.selector, pod.metadata.labels), "selector misses its pods");
  expect(pod.spec.securityContext.runAsNonRoot === true, "runAsNonRoot is not set");
  for (const c of pod.spec.containers) {
    const ports = (c.ports || []).map((p) => p.containerPort);
    // Kubernetes' grpc probe speaks no TLS: the probes run `cablesim health`
    // over TLS on the container's port (tests/deploy_start_test.py runs them).
    for (const probe of ["readinessProbe", "livenessProbe"]) {
      const command = c[probe] && c[probe].exec && c[probe].exec.command;
      expect(command && command.slice(0, 2).join(" ") === "cablesim health",
             `${c.name}: ${probe} is not \`cablesim health\``);
      const server = command[command.indexOf("--server") + 1] || "";
      expect(ports.includes(Number(server.split(":").pop())), `${c.name}: ${probe} not on a container port`);
      expect(command.includes("--tls-ca"), `${c.name}: ${probe} without --tls-ca`);
    }
    for (const flag of ["--tls-cert=", "--tls-key=", "--token-file="]) {
      expect(c.args.some((a) => a.startsWith(flag)), `${c.name}: no ${flag}`);
    }
    const mounted = (c.volumeMounts || []).map((m) => m.name);
    const secretNames = deployment.spec.template.spec.volumes
        .filter((v) => mounted.includes(v.name) && v.projected)
        .flatMap((v) => v.projected.sources.map((src) => src.secret && src.secret.name));
    for (const name of ["cablesim-tls", "cablesim-tokens"]) {
      expect(secretNames.includes(name), `${c.name}: Secret ${name} is not mounted`);
    }
    for (const part of ["requests", "limits"]) {
      for (const resource of ["cpu", "memory"]) {
        expect(c.resources && c.resources[part] && c.resources[part][resource],
               `${c.name}: no ${part}.${resource}`);
      }
    }
    expect(c.args.includes("--store=$(CABLESIM_STORE)"), `${c.name}: no --store=$(CABLESIM_STORE)`);
    const env = Object.fromEntries(c.env.map((e) => [e.name, e]));
    for (const [name, key] of [["CABLESIM_STORE", "store-url"], ["PGPASSWORD", "password"]]) {
      const ref = env[name] && env[name].valueFrom && env[name].valueFrom.secretKeyRef;
      expect(ref, `${c.name}: ${name} is not from a Secret`);
      const [secret] = find("Secret", ref.name);
      expect(ref.key === key && key in secret.stringData, `${c.name}: ${name}: no key ${key}`);
    }
    expect(String(secret(c)).startsWith("postgresql://"), "the Secret's store-url is no postgresql URL");
  }
  function secret(c) {
    const ref = c.env.find((e) => e.name === "CABLESIM_STORE").valueFrom.secretKeyRef;
    return find("Secret", ref.name)[0].stringData[ref.key];
  }
});

check("kubernetes: a headless Service and a PodDisruptionBudget select the server pods", () => {
  const [deployment] = find("Deployment", "cablesim-server");
  const labels = deployment.spec.template.metadata.labels;
  const [service] = find("Service", "cablesim-server");
  expect(service.spec.clusterIP === "None", "the Service is not headless (clusterIP: None)");
  expect(selects(service.spec.selector, labels), "the Service does not select the server pods");
  const portNames = deployment.spec.template.spec.containers.flatMap((c) => c.ports.map((p) => p.name));
  for (const p of service.spec.ports) {
    expect(portNames.includes(p.targetPort), `Service port ${p.name}: no container port ${p.targetPort}`);
  }
  const [pdb] = find("PodDisruptionBudget");
  expect(selects(pdb.spec.selector, labels), "the PodDisruptionBudget does not select the server pods");
  const allowed = pdb.spec.maxUnavailable !== undefined
      ? pdb.spec.maxUnavailable
      : deployment.spec.replicas - pdb.spec.minAvailable;
  expect(allowed >= 1 && allowed < deployment.spec.replicas,
         "the PodDisruptionBudget blocks every drain or allows all servers down");
});

check("kubernetes: pod I of the Indexed Job runs sweep item I (run here)", () => {
  const [job] = find("Job", "cablesim-sweep");
  expect(job.spec.completionMode === "Indexed", "completionMode is not Indexed");
  const pod = job.spec.template.spec;
  const [container] = pod.containers;
  const script = container.command.join(" ");
  expect(/--item "\$JOB_COMPLETION_INDEX"/.test(script), "the command does not pass --item $JOB_COMPLETION_INDEX");
  const mounts = Object.fromEntries(container.volumeMounts.map((m) => [m.name, m.mountPath]));
  const volumes = Object.fromEntries(pod.volumes.map((v) => [v.name, v]));
  const sweepVolume = Object.keys(mounts).find((n) => volumes[n].configMap);
  const resultsVolume = Object.keys(mounts).find((n) => volumes[n].persistentVolumeClaim);
  expect(sweepVolume && resultsVolume, "no ConfigMap or no PersistentVolumeClaim mounted");
  find("PersistentVolumeClaim", volumes[resultsVolume].persistentVolumeClaim.claimName);
  const [configMap] = find("ConfigMap", volumes[sweepVolume].configMap.name);
  const tmp = fs.mkdtempSync(path.join(os.tmpdir(), "cablesim-deploy-"));
  try {
    const sweepDir = path.join(tmp, "sweep");
    const resultsDir = path.join(tmp, "results");
    fs.mkdirSync(sweepDir);
    fs.mkdirSync(resultsDir);
    // As the kubelet mounts a ConfigMap: each key a symbolic link into a
    // timestamped directory reached through ..data.
    fs.mkdirSync(path.join(sweepDir, "..2026_01_01_00_00_00.1"));
    fs.symlinkSync("..2026_01_01_00_00_00.1", path.join(sweepDir, "..data"));
    for (const [name, text] of Object.entries(configMap.data)) {
      fs.writeFileSync(path.join(sweepDir, "..data", name), text);
      fs.symlinkSync(path.join("..data", name), path.join(sweepDir, name));
    }
    // The mount paths as they start a path in the command, moved to here.
    const moved = (a, mount, dir) => a.replace(new RegExp(`(^|[\\s"'])${mount}(?=/)`, "g"), `$1${dir}`);
    const local = container.command.map((a) =>
        moved(moved(a, mounts[sweepVolume], sweepDir), mounts[resultsVolume], resultsDir));
    const run = (index) => spawnSync(local[0], local.slice(1), {
      encoding: "utf8",
      env: { ...process.env, JOB_COMPLETION_INDEX: String(index),
             PATH: `${binDir}:${process.env.PATH}` },
    });
    const last = job.spec.completions - 1;
    const ok = run(last);
    expect(ok.status === 0, `pod ${last} exited ${ok.status}: ${ok.stderr}`);
    const rows = fs.readFileSync(path.join(resultsDir, `item-${last}.csv`), "utf8").trim().split("\n");
    expect(rows.length === 2 && rows[0].startsWith("index,job_id,state,") &&
           rows[1].startsWith(`${last},j-`), `item-${last}.csv: ${rows.join(" | ")}`);
    const beyond = run(job.spec.completions);
    expect(beyond.status === 2 && beyond.stderr.includes("is not an item of"),
           `completions ${job.spec.completions} is fewer than the sweep's items ` +
           `(pod ${job.spec.completions} exited ${beyond.status})`);
  } finally {
    fs.rmSync(tmp, { recursive: true, force: true });
  }
});

check("kubernetes: cert-manager's Certificate makes the Secret the servers mount", () => {
  const [certificate] = find("Certificate", "cablesim-server");
  expect(certificate.spec.secretName === "cablesim-tls", "secretName is not cablesim-tls");
  expect(certificate.spec.issuerRef && certificate.spec.issuerRef.name, "no issuerRef");
  expect(certificate.spec.dnsNames.includes("localhost"), "no localhost (the probes' name)");
  const [service] = find("Service", "cablesim-server");
  expect(certificate.spec.dnsNames.includes(service.metadata.name), "the Service's name is not covered");
  const [tokens] = find("Secret", "cablesim-tokens");
  expect(tokens.stringData && tokens.stringData.tokens, "cablesim-tokens has no key tokens");
});

check("kubernetes: the HorizontalPodAutoscaler scales the server Deployment on its queue and CPU", () => {
  const [hpa] = find("HorizontalPodAutoscaler", "cablesim-server");
  const [deployment] = find("Deployment", hpa.spec.scaleTargetRef.name);
  expect(hpa.spec.scaleTargetRef.kind === "Deployment", "the target is not a Deployment");
  expect(deployment.spec.template.spec.containers.every((c) => c.resources.requests.cpu),
         "utilization needs CPU requests on every container");
  expect(hpa.spec.minReplicas >= 1 && hpa.spec.maxReplicas > hpa.spec.minReplicas, "replica bounds");
  const external = hpa.spec.metrics.find((m) => m.type === "External");
  expect(external && external.external.metric.name === "cablesim_jobs_queued", "no queue metric");
  for (const c of deployment.spec.template.spec.containers) {
    const flag = c.args.find((a) => a.startsWith("--metrics-listen="));
    expect(flag, `${c.name}: no --metrics-listen`);
    const port = Number(flag.split(":").pop());
    expect(c.ports.some((p) => p.containerPort === port), `${c.name}: metrics port ${port} not declared`);
  }
});

check("kubernetes: sweep-job.py derives completions from the sweep", () => {
  const sweepFile = path.join(sourceDir, "sweeps", "pendulum-resolution.json");
  const out = execFileSync("python3", [path.join(manifestDir, "sweep-job.py"), sweepFile],
                           { encoding: "utf8" });
  const docs = YAML.parseAllDocuments(out).map((d) => d.toJS());
  const sweep = JSON.parse(fs.readFileSync(sweepFile, "utf8"));
  const items = sweep.axes.reduce((n, a) => n * a.values.length, 1);
  const job = docs.find((d) => d.kind === "Job");
  expect(job.spec.completions === items, `completions ${job.spec.completions}, the sweep has ${items} items`);
  const map = docs.find((d) => d.kind === "ConfigMap");
  expect(JSON.parse(map.data["sweep.json"]).base_file in map.data, "the base scene is not beside sweep.json");
});

// ---- compose -----------------------------------------------------------------

check("compose.yaml: PostgreSQL and two servers on its queue, with health checks", () => {
  const [compose] = parseYaml(path.join(deployDir, "compose.yaml"), { merge: true });
  const services = compose.services;
  expect(services.postgres && services.postgres.healthcheck, "no postgres service with a healthcheck");
  const servers = Object.entries(services).filter(
      ([, s]) => (s.command || []).some((a) => a.startsWith("--listen")));
  expect(servers.length === 2, `${servers.length} servers, not 2`);
  const hostPorts = new Set();
  for (const [name, s] of servers) {
    expect(s.command.some((a) => a.startsWith("--store=postgresql://") && a.includes("@postgres:")),
           `${name}: no --store=postgresql://...@postgres:...`);
    expect(s.environment.PGPASSWORD, `${name}: no PGPASSWORD`);
    expect(s.depends_on.postgres.condition === "service_healthy", `${name}: starts before postgres is healthy`);
    expect(s.healthcheck.test.join(" ").includes("cablesim health"), `${name}: no gRPC health check`);
    expect(fs.existsSync(path.join(deployDir, s.build.context, s.build.dockerfile)),
           `${name}: no ${s.build.dockerfile} under ${s.build.context}`);
    for (const p of s.ports) hostPorts.add(p.split(":").slice(0, -1).join(":"));
  }
  expect(hostPorts.size === 2, "the two servers publish the same host port");
});

// ---- Dockerfile --------------------------------------------------------------

check("Dockerfile: Debian 12 stages, non-root user, gRPC health check, sources and packages", () => {
  const text = fs.readFileSync(path.join(deployDir, "Dockerfile"), "utf8").replace(/\\\n/g, " ");
  const lines = text.split("\n").map((l) => l.trim()).filter((l) => l && !l.startsWith("#"));
  const from = lines.filter((l) => /^FROM /i.test(l));
  expect(from.length >= 2, "not multi-stage");
  for (const f of from) expect(/^FROM debian:12(-slim)?\b/.test(f), `not Debian 12: ${f}`);
  const user = lines.filter((l) => /^USER /.test(l)).pop();
  expect(user && !/^USER (0|root)\b/.test(user), "the final stage does not run as a non-root user");
  expect(lines.indexOf(user) > lines.lastIndexOf(from[from.length - 1]), "USER is not in the last stage");
  const health = lines.find((l) => /^HEALTHCHECK /.test(l));
  expect(health && /"cablesim", "health"/.test(health), "no HEALTHCHECK through cablesim health");
  for (const l of lines.filter((l) => /^COPY /.test(l) && !/--from=/.test(l))) {
    const sources = l.split(/\s+/).slice(1, -1);
    for (const s of sources) expect(fs.existsSync(path.join(sourceDir, s)), `COPY ${s}: no such file`);
  }
  const installs = lines.filter((l) => l.includes("apt-get install"));
  const stagePackages = installs.map((l) => l.split("apt-get install")[1].split("&&")[0]
      .split(/\s+/).filter((w) => w && !w.startsWith("-")));
  const all = stagePackages.flat();
  const shown = spawnSync("apt-cache", ["show", "--no-all-versions", ...all], { encoding: "utf8" });
  for (const p of all) {
    expect(new RegExp(`^Package: ${p.replace(/\+/g, "\\+")}$`, "m").test(shown.stdout), `no Debian package ${p}`);
  }
  // The runtime stage (the last install) must provide every shared library
  // the binaries link: the packages owning them are in the dependency
  // closure of its list, or in every Debian image (libc6, libgcc-s1,
  // libstdc++6).
  const runtime = stagePackages[stagePackages.length - 1];
  const closure = new Set(execFileSync("apt-cache", ["depends", "--recurse", "--no-recommends",
      "--no-suggests", "--no-conflicts", "--no-breaks", "--no-replaces", "--no-enhances",
      ...runtime], { encoding: "utf8" }).split("\n").filter((l) => /^\S/.test(l))
      .map((l) => l.replace(/:.*$/, "")));
  for (const base of ["libc6", "libgcc-s1", "libstdc++6"]) closure.add(base);
  const libs = new Set();
  for (const binary of ["cablesim-server", "cablesim"]) {
    for (const l of execFileSync("ldd", [path.join(binDir, binary)], { encoding: "utf8" }).split("\n")) {
      const m = l.match(/=> (\/\S+)/);
      if (m) libs.add(m[1]);
    }
  }
  // One dpkg -S for every library, under each name it may be registered by
  // (Debian 12 merges /lib into /usr/lib).
  const names = new Map();
  for (const lib of libs) {
    for (const n of [lib, "/usr" + lib, fs.realpathSync(lib), "/usr" + fs.realpathSync(lib)]) {
      names.set(n, lib);
    }
  }
  const owners = new Map();
  const found = spawnSync("dpkg", ["-S", ...names.keys()], { encoding: "utf8" }).stdout;
  for (const line of found.split("\n")) {
    const m = line.match(/^([^:,]+)(?::[^:]+)?: (\/\S+)$/);
    if (m && names.has(m[2])) owners.set(names.get(m[2]), m[1]);
  }
  for (const lib of libs) {
    const owner = owners.get(lib);
    expect(owner, `${lib} belongs to no Debian package`);
    expect(closure.has(owner), `the binaries link ${lib} (${owner}), not in the runtime stage`);
  }
});

console.log(`${passed} passed, ${failed} failed`);
process.exit(failed === 0 ? 0 : 1);
