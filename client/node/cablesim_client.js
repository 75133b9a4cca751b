// A small Node.js client of the cablesim service (proto/cablesim/v1/
// service.proto), with @grpc/grpc-js and @grpc/proto-loader.
//
// Scenes travel as JSON text (`scene_json`): the server parses them with
// the same strict parser as `cablesim validate`, so an unknown enum name or
// a misspelt field is an error here too. (Building the Scene message with
// protobufjs instead would silently turn an unknown enum such as
// "bending": "CURVY" into the default.)
//
//   const cablesim = require('./cablesim_client');
//   const client = cablesim.connect('127.0.0.1:50051');
//   const check = await cablesim.validate(client, fs.readFileSync('scene.json', 'utf8'));
//   const run = await cablesim.run(client, sceneText);   // {columns, rows, summary}
//   const session = await cablesim.couple(client, sceneText, {points});
//   const reply = await session.step(0.05, points);      // reply.forces [N]

'use strict';

const path = require('path');
const grpc = require('@grpc/grpc-js');
const protoLoader = require('@grpc/proto-loader');

const PROTO_DIR = path.join(__dirname, '..', '..', 'proto');

// The token in a token file: the first word of its first line that is not
// a # comment (as `cablesim --token-file` and the Python client read it).
function readToken(file) {
  for (const raw of require('fs').readFileSync(file, 'utf8').split('\n')) {
    const line = raw.trim();
    if (line && !line.startsWith('#')) return line.split(/\s+/)[0];
  }
  throw new Error(`${file}: no token`);
}

// A CablesimService stub for `address` (host:port). Options: `tlsCa`, a CA
// certificate file (PEM) the server's certificate is checked against (TLS;
// without it, plaintext); `token` or `tokenFile`, a bearer token sent with
// every call (metadata `authorization: Bearer TOKEN`).
function connect(address, {tlsCa, token, tokenFile} = {}) {
  const definition = protoLoader.loadSync('cablesim/v1/service.proto', {
    includeDirs: [PROTO_DIR],
    keepCase: true,  // field names as in the .proto (scene_json, frames_per_batch)
    longs: Number,
    enums: String,
    defaults: true,
  });
  const cablesim = grpc.loadPackageDefinition(definition).cablesim.v1;
  if (tokenFile) token = readToken(tokenFile);
  const credentials = tlsCa ? grpc.credentials.createSsl(require('fs').readFileSync(tlsCa))
                            : grpc.credentials.createInsecure();
  const client = new cablesim.CablesimService(address, credentials);
  client.cablesimToken = token;  // sent with every call (metadataFor)
  return client;
}

// Per-call metadata: the bearer token, if any.
function metadataFor(client) {
  const metadata = new grpc.Metadata();
  if (client.cablesimToken) metadata.add('authorization', `Bearer ${client.cablesimToken}`);
  return metadata;
}

// Validate: resolves to the ValidateResponse ({valid, model, errors}).
function validate(client, sceneJson) {
  return new Promise((resolve, reject) => {
    client.Validate({scene_json: sceneJson}, metadataFor(client), (error, response) =>
      error ? reject(error) : resolve(response));
  });
}

// Run: resolves to {columns, rows (arrays of numbers, one per frame),
// summary}; rejects with the gRPC error (code 3, INVALID_ARGUMENT, for a bad
// scene, its message naming the field).
function run(client, sceneJson) {
  return new Promise((resolve, reject) => {
    const result = {columns: [], rows: [], summary: null};
    const call = client.Run({scene_json: sceneJson}, metadataFor(client));
    call.on('data', (event) => {
      if (event.header) {
        result.columns = event.header.columns;
      } else if (event.frames) {
        const width = result.columns.length;
        const values = event.frames.values;
        for (let r = 0; r < event.frames.rows; ++r) {
          result.rows.push(values.slice(r * width, (r + 1) * width));
        }
      } else if (event.summary) {
        result.summary = event.summary;
      }
    });
    call.on('error', reject);
    call.on('end', () => resolve(result));
  });
}

// Couple: opens a coupling session (the Couple stream) of `sceneJson`, a
// DYNAMIC scene with coupled supports or bodies, with the coupled points
// at `points` ([{position: {x, y, z}, velocity: {x, y, z}}, ...], one per
// coupled support in the scene's order of its joints) and the coupled
// bodies at `bodies` ([{position, orientation: {w, x, y, z}, velocity,
// angular_velocity}, ...]). Resolves to a session once the server has
// answered the open message:
//   session.open        the first CoupleResponse (the forces at t = 0, the
//                       model, scene_positions, max_jump_m, end_time_s ...)
//   session.step(dt_s, points, bodies)
//                       resolves to the step's CoupleResponse (forces: the
//                       mean over the step [N], end_forces, body_forces,
//                       host_work_j ...). A bad step (a wrong count of
//                       points, a jump too long) resolves with `error` set
//                       ({code, path, message}) and leaves the session as it
//                       was; a step the lines cannot take rejects (ABORTED).
//   session.close()     ends the session (the client's side of the stream).
// Rejects with the gRPC error when the scene is refused (code 3,
// INVALID_ARGUMENT, naming the field). Replies come in order, one per
// message, so each step's promise takes the next reply.
function couple(client, sceneJson, {points = [], bodies = [], lines = false, strict = false} = {}) {
  const call = client.Couple(metadataFor(client));
  const waiting = [];  // {resolve, reject} per message sent, in order
  let failure = null;
  call.on('data', (response) => {
    const next = waiting.shift();
    if (next) next.resolve(response);
  });
  const failAll = (error) => {
    failure = error;
    while (waiting.length) waiting.shift().reject(error);
  };
  call.on('error', failAll);
  call.on('end', () => failAll(failure || new Error('cablesim: the Couple stream ended')));
  const send = (request) => new Promise((resolve, reject) => {
    if (failure) return reject(failure);
    waiting.push({resolve, reject});
    call.write(request);
  });
  return send({open: {scene_json: sceneJson, points, bodies, lines, strict}}).then((open) => ({
    open,
    step: (dt_s, stepPoints = [], stepBodies = []) =>
      send({step: {dt_s, points: stepPoints, bodies: stepBodies}}),
    close: () => call.end(),
  }));
}

module.exports = {connect, readToken, validate, run, couple};

// As a program: node cablesim_client.js (validate | run) SCENE.json
//   --server HOST:PORT [--tls-ca CA.pem] [--token-file FILE]
// prints the ValidateResponse, or the run's summary, as one JSON line;
// exit 1 when the call fails, 2 on a usage error.
if (require.main === module) {
  const args = process.argv.slice(2);
  const flags = {};
  const rest = [];
  for (let i = 0; i < args.length; ++i) {
    const m = /^--(server|tls-ca|token-file)(?:=(.*))?$/.exec(args[i]);
    if (m) {
      flags[m[1]] = m[2] !== undefined ? m[2] : args[++i];
    } else {
      rest.push(args[i]);
    }
  }
  if (rest.length !== 2 || !['validate', 'run'].includes(rest[0]) || !flags.server) {
    console.error('usage: node cablesim_client.js (validate | run) SCENE.json --server HOST:PORT ' +
                  '[--tls-ca CA.pem] [--token-file FILE]');
    process.exit(2);
  }
  const client = connect(flags.server, {tlsCa: flags['tls-ca'], tokenFile: flags['token-file']});
  const text = require('fs').readFileSync(rest[1], 'utf8');
  (rest[0] === 'validate' ? validate(client, text) : run(client, text).then((r) => r.summary))
      .then((out) => console.log(JSON.stringify(out)))
      .catch((error) => {
        console.error(`cablesim: ${error.message}`);
        process.exit(1);
      });
}
