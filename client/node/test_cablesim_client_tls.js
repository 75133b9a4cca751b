// The Node.js client against a cablesim-server serving TLS with a
// certificate signed by a CA made now with openssl, and bearer tokens
// (--token-file): with --tls-ca and the token the calls succeed (library
// and command line); without the token they are UNAUTHENTICATED; against a
// CA that did not sign the server's certificate the handshake fails.
// CTest runs this (node_client_tls_test) when node and openssl are
// installed.

'use strict';

const assert = require('assert');
const childProcess = require('child_process');
const fs = require('fs');
const os = require('os');
const path = require('path');
const cablesim = require('./cablesim_client');

const SOURCE = process.env.CABLESIM_SOURCE_DIR;
const BIN = process.env.CABLESIM_BIN_DIR;

function openssl(dir, args) {
  childProcess.execFileSync('openssl', args, {cwd: dir, stdio: ['ignore', 'ignore', 'ignore']});
}

// ca.pem signs server.pem (for 127.0.0.1); other.pem is a CA that signs nothing.
function makeCertificates(dir) {
  for (const ca of ['ca', 'other']) {
    openssl(dir, ['req', '-x509', '-newkey', 'rsa:2048', '-nodes', '-keyout', `${ca}.key`,
                  '-out', `${ca}.pem`, '-days', '1', '-subj', `/CN=cablesim-test-${ca}`]);
  }
  fs.writeFileSync(path.join(dir, 'server.ext'), 'subjectAltName=DNS:localhost,IP:127.0.0.1\n');
  openssl(dir, ['req', '-newkey', 'rsa:2048', '-nodes', '-keyout', 'server.key', '-out',
                'server.csr', '-subj', '/CN=localhost']);
  openssl(dir, ['x509', '-req', '-in', 'server.csr', '-CA', 'ca.pem', '-CAkey', 'ca.key',
                '-CAcreateserial', '-out', 'server.pem', '-days', '1', '-extfile', 'server.ext']);
}

async function waitForPortFile(file, server) {
  while (!(fs.existsSync(file) && fs.readFileSync(file, 'utf8').trim())) {
    if (server.exitCode !== null || server.signalCode !== null) {
      throw new Error(`cablesim-server exited (${server.exitCode ?? server.signalCode})`);
    }
    await new Promise((r) => setTimeout(r, 10));
  }
}

async function main() {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'cablesim-node-tls-'));
  makeCertificates(dir);
  fs.writeFileSync(path.join(dir, 'tokens'), 'node-test-token-0123456789 tenant-a\n', {mode: 0o600});
  fs.writeFileSync(path.join(dir, 'client-token'), '# the client\'s token\nnode-test-token-0123456789\n');
  const portFile = path.join(dir, 'port');
  const server = childProcess.spawn(
      path.join(BIN, 'cablesim-server'),
      ['--listen=127.0.0.1:0', `--data-dir=${dir}/data`, `--port-file=${portFile}`,
       '--workers=1', `--tls-cert=${dir}/server.pem`, `--tls-key=${dir}/server.key`,
       `--token-file=${dir}/tokens`],
      {stdio: ['ignore', 'inherit', 'inherit']});
  try {
    await waitForPortFile(portFile, server);
    const address = `127.0.0.1:${fs.readFileSync(portFile, 'utf8').trim()}`;
    const scene = JSON.parse(
        fs.readFileSync(path.join(SOURCE, 'scenes', 'falling-pendulum.json'), 'utf8'));
    scene.solver.duration = 0.01;
    const text = JSON.stringify(scene);

    const tls = {tlsCa: path.join(dir, 'ca.pem')};
    const good = cablesim.connect(address, {...tls, tokenFile: path.join(dir, 'client-token')});
    assert.strictEqual((await cablesim.validate(good, text)).valid, true);
    assert.strictEqual((await cablesim.run(good, text)).summary.status, 'ok');

    await assert.rejects(cablesim.validate(cablesim.connect(address, tls), text),
                         (error) => error.code === 16);  // UNAUTHENTICATED
    await assert.rejects(
        cablesim.validate(cablesim.connect(address, {...tls, token: 'wrong-token-0123456789'}),
                          text),
        (error) => error.code === 16);
    await assert.rejects(
        cablesim.validate(cablesim.connect(address, {tlsCa: path.join(dir, 'other.pem'),
                                                     tokenFile: path.join(dir, 'client-token')}),
                          text),
        (error) => error.code === 14);  // UNAVAILABLE: the handshake failed

    // The command line, as `cablesim --tls-ca --token-file`.
    const sceneFile = path.join(dir, 'scene.json');
    fs.writeFileSync(sceneFile, text);
    const out = childProcess.execFileSync(
        process.execPath,
        [path.join(__dirname, 'cablesim_client.js'), 'run', sceneFile, '--server', address,
         '--tls-ca', path.join(dir, 'ca.pem'), '--token-file', path.join(dir, 'client-token')],
        {encoding: 'utf8'});
    assert.strictEqual(JSON.parse(out).status, 'ok', out);
    console.log('node client TLS and token: ok');
  } finally {
    server.kill('SIGKILL');
    fs.rmSync(dir, {recursive: true, force: true});
  }
}

main().catch((error) => {
  console.error(error);
  process.exit(1);
});
