// Reads a LAZ file with laz-perf (the LASzip-compatible codec PDAL uses, compiled to
// WebAssembly), a LAZ reader independent of neuralmesh, for neuralmesh's LAZ tests. Writes every
// decompressed point record, in file order, concatenated (LENGTH bytes each) to OUT, and prints
// one line "FORMAT LENGTH COUNT": the point data format as laz-perf reports it (without the
// compression bit 0x80), the record length and the point count. Exits 1 with the reader's error on stderr when it refuses
// the file. laz-perf itself also reads an uncompressed LAS file; this script refuses one.
//
// Usage: node tests/tools/laz_reader.mjs FILE.laz OUT.records
import { readFileSync, writeFileSync } from "fs";
import createLazPerf from "./node_modules/laz-perf/lib/node/laz-perf.js";

// The record length of each point format laz-perf decodes.
const BASE_LENGTH = { 0: 20, 1: 28, 2: 26, 3: 34, 6: 30, 7: 36, 8: 38 };

try {
  const file = readFileSync(process.argv[2]);
  const lazPerf = await createLazPerf();
  const filePointer = lazPerf._malloc(file.length);
  const laszip = new lazPerf.LASZip();
  let recordPointer = 0;
  try {
    if (!filePointer) throw new Error(`cannot allocate ${file.length} bytes`);
    lazPerf.HEAPU8.set(file, filePointer);
    laszip.open(filePointer, file.length);
    if (!(file[104] & 0x80)) throw new Error("not LASzip-compressed: no compression bit 0x80");
    const format = laszip.getPointFormat();
    const length = laszip.getPointLength();
    const count = laszip.getCount(); // the 64-bit count of a LAS 1.4 header, else the legacy one
    // laz-perf has no decompressor for formats 4, 5, 9 and 10: getPoint would trap.
    if (!(format in BASE_LENGTH)) throw new Error(`cannot decode point format ${format}`);
    if (length < BASE_LENGTH[format]) {
      throw new Error(`record length ${length} for format ${format}`);
    }
    const records = Buffer.alloc(length * count);
    recordPointer = lazPerf._malloc(length);
    for (let i = 0; i < count; i++) {
      laszip.getPoint(recordPointer);
      records.set(lazPerf.HEAPU8.subarray(recordPointer, recordPointer + length), i * length);
    }
    writeFileSync(process.argv[3], records);
    process.stdout.write(`${format} ${length} ${count}\n`);
  } finally {
    laszip.delete();
    lazPerf._free(recordPointer);
    lazPerf._free(filePointer);
  }
} catch (error) {
  // laz-perf is built without C++ exceptions: its refusals arrive as a string with an address.
  process.stderr.write(`laz-perf: ${error?.message ?? error}\n`);
  process.exit(1);
}
