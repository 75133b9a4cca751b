// Runs the Node.js client against a live cablesim-server on a loopback
// port: a scene given as JSON text runs; an unknown enum name and a value of
// the wrong kind are refused naming the field, as `cablesim validate` does.
// CTest runs this (node_client_test) when node is installed.

'use strict';

const assert = require('assert');
const childProcess = require('child_process');
const fs = require('fs');
const os = require('os');
const path = require('path');
let cablesim;
try {
  cablesim = require('./cablesim_client');
} catch (error) {
  console.error(`${error.message}\nThe npm packages are missing: run 'npm ci' in client/node ` +
                '(deploy/install-deps.sh does when node is installed).');
  process.exit(1);
}

const SOURCE = process.env.CABLESIM_SOURCE_DIR;
const BIN = process.env.CABLESIM_BIN_DIR;

// Until the server has written its port file (it writes it whole, by a
// rename) or has exited: no time limit that a busy machine could exceed (a
// hung start is CTest's timeout).
async function waitForPortFile(file, server) {
  while (!(fs.existsSync(file) && fs.readFileSync(file, 'utf8').trim())) {
    if (server.exitCode !== null || server.signalCode !== null) {
      throw new Error(`cablesim-server exited (${server.exitCode ?? server.signalCode}) ` +
                      `before writing ${file}`);
    }
    await new Promise((r) => setTimeout(r, 10));
  }
}

// The Couple stream from Node: the three-line floater's fairleads held at
// the scene's points. The forces at t = 0 (lines from their static
// equilibrium) must be minus the support reactions of the same scene solved
// by a STATIC Run (the reaction is the support's force on the line; the
// Couple force the line's on the point), to 1e-6 of their size (two Newton
// solves to their tolerance from different starts); a step advances the
// time; a step with a wrong count of points is answered with an error
// naming `points` and leaves the session usable.
async function checkCouple(client) {
  const scene = JSON.parse(
      fs.readFileSync(path.join(SOURCE, 'tests', 'data', 'couple_floater_coupled.json'), 'utf8'));
  const fairleads = scene.cables.map((c) => c.points[c.points.length - 1]);
  const points = fairleads.map((p) => ({position: {x: p.x || 0, y: p.y || 0, z: p.z || 0}}));
  const session = await cablesim.couple(client, JSON.stringify(scene), {points});
  assert.strictEqual(session.open.forces.length, 3);
  assert.strictEqual(session.open.error, null);

  const statics = JSON.parse(JSON.stringify(scene));
  statics.solver = {analysis: 'STATIC', load_steps: scene.solver.load_steps};
  statics.output = {reactions: true};
  statics.joints.forEach((j) => delete j.coupled);
  const solved = await cablesim.run(client, JSON.stringify(statics));
  assert.strictEqual(solved.summary.status, 'ok');
  const last = solved.rows[solved.rows.length - 1];
  session.open.coupled_joints.forEach((joint, k) => {
    const f = session.open.forces[k];
    const r = ['x', 'y', 'z'].map((a) => last[solved.columns.indexOf(`joints[${joint}].f${a}`)]);
    const size = Math.hypot(...r);
    assert.ok(size > 1e3, `joints[${joint}]: reaction ${r}`);
    ['x', 'y', 'z'].forEach((a, i) => assert.ok(Math.abs(f[a] + r[i]) <= 1e-6 * size,
                                                `fairlead ${k} ${a}: ${f[a]} against ${-r[i]}`));
  });

  const step = await session.step(0.05, points);
  assert.strictEqual(step.error, null);
  assert.ok(Math.abs(step.time_s - 0.05) < 1e-12, `time ${step.time_s}`);
  assert.ok(step.steps > 0);
  const bad = await session.step(0.05, points.slice(0, 2));
  assert.strictEqual(bad.error.code, 'INVALID_ARGUMENT');
  assert.match(bad.error.path, /points/);
  const again = await session.step(0.05, points);
  assert.strictEqual(again.error, null);
  assert.ok(Math.abs(again.time_s - 0.1) < 1e-12, `time ${again.time_s}`);
  session.close();
}

async function main() {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'cablesim-node-'));
  const portFile = path.join(dir, 'port');
  const server = childProcess.spawn(
      path.join(BIN, 'cablesim-server'),
      ['--listen=127.0.0.1:0', `--data-dir=${dir}`, `--port-file=${portFile}`, '--workers=1'],
      {stdio: ['ignore', 'inherit', 'inherit']});
  try {
    await waitForPortFile(portFile, server);
    const port = fs.readFileSync(portFile, 'utf8').trim();
    const client = cablesim.connect(`127.0.0.1:${port}`);

    const scene = JSON.parse(
        fs.readFileSync(path.join(SOURCE, 'scenes', 'falling-pendulum.json'), 'utf8'));
    scene.solver.duration = 0.01;
    const text = JSON.stringify(scene);

    const ok = await cablesim.validate(client, text);
    assert.strictEqual(ok.valid, true, JSON.stringify(ok));

    const run = await cablesim.run(client, text);
    assert.strictEqual(run.summary.status, 'ok');
    assert.strictEqual(run.columns[0], 't');
    assert.ok(run.columns.includes('energy.total'));
    assert.strictEqual(run.rows.length, Number(run.summary.frames));

    scene.cables[0].bending = 'CURVY';
    const curvy = await cablesim.validate(client, JSON.stringify(scene));
    assert.strictEqual(curvy.valid, false);
    assert.strictEqual(curvy.errors[0].path, 'scene_json');
    assert.match(curvy.errors[0].message, /CURVY/);

    await assert.rejects(cablesim.run(client, '{"cables": {"name": "c"}}'), (error) => {
      assert.strictEqual(error.code, 3);  // INVALID_ARGUMENT
      assert.match(error.details, /cables: must be a list/);
      return true;
    });
    await checkCouple(client);
    client.close();
    console.log('node client: ok');
  } finally {
    if (server.exitCode === null && server.signalCode === null) {
      const exited = new Promise((r) => server.on('exit', r));
      server.kill('SIGTERM');
      await exited;
    }
    fs.rmSync(dir, {recursive: true, force: true});
  }
}

main().catch((error) => {
  console.error(error);
  process.exit(1);
});
