// Reads an E57 file with web-e57 (the Rust e57 crate compiled to WebAssembly), an E57 reader
// independent of neuralmesh, for tests/core/io/e57_independent_reader_test.cc. Prints what
// web-e57 converts the file to: FORMAT "XYZ" (one "x y z [r g b]" line a point, the scans'
// poses applied) or "XML" (the file's XML section). Exits 1 with the reader's error on stderr
// when it refuses the file.
//
// Usage: node tests/tools/e57_reader.mjs FILE [XYZ|XML]
import { readFileSync } from "fs";
import * as glue from "./node_modules/web-e57/e57_bg.js";

const wasm = readFileSync(new URL("./node_modules/web-e57/e57_bg.wasm", import.meta.url));
const { instance } = await WebAssembly.instantiate(wasm, { "./e57_bg.js": glue });
glue.__wbg_set_wasm(instance.exports);
try {
  const converted = glue.convertE57(new Uint8Array(readFileSync(process.argv[2])),
                                    process.argv[3] || "XYZ");
  process.stdout.write(typeof converted === "string" ? converted : Buffer.from(converted));
} catch (error) {
  process.stderr.write(`web-e57: ${error}\n`);
  process.exit(1);
}
