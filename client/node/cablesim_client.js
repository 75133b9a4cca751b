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

'use strict';

const path = require('path');
const grpc = require('@grpc/grpc-js');
const protoLoader = require('@grpc/proto-loader');

const PROTO_DIR = path.join(__dirname, '..', '..', 'proto');

// A CablesimService stub for `address` (host:port), without TLS.
function connect(address) {
  const definition = protoLoader.loadSync('cablesim/v1/service.proto', {
    includeDirs: [PROTO_DIR],
    keepCase: true,  // field names as in the .proto (scene_json, frames_per_batch)
    longs: Number,
    enums: String,
    defaults: true,
  });
  const cablesim = grpc.loadPackageDefinition(definition).cablesim.v1;
  return new cablesim.CablesimService(address, grpc.credentials.createInsecure());
}

// Validate: resolves to the ValidateResponse ({valid, model, errors}).
function validate(client, sceneJson) {
  return new Promise((resolve, reject) => {
    client.Validate({scene_json: sceneJson}, (error, response) =>
      error ? reject(error) : resolve(response));
  });
}

// Run: resolves to {columns, rows (arrays of numbers, one per frame),
// summary}; rejects with the gRPC error (code 3, INVALID_ARGUMENT, for a bad
// scene, its message naming the field).
function run(client, sceneJson) {
  return new Promise((resolve, reject) => {
    const result = {columns: [], rows: [], summary: null};
    const call = client.Run({scene_json: sceneJson});
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

module.exports = {connect, validate, run};
