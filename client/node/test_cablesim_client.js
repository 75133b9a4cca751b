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
