// Decodes LCM messages the way lcm-spy does: finds each message's class by its fingerprint
// through lcm.spy.LCMTypeDatabase (which scans CLASSPATH), decodes it, and prints every field in
// the form of tests/support/field_dump.hpp, so a C++ test can compare field values.
//
// Usage: java -cp <types jar>:lcm.jar:jchart2d.jar:<this jar> LcmDump FILE...
// Each FILE holds one encoded message. Output per file: "type=<name>", "fingerprint=<hex>" (the
// class's LCM_FINGERPRINT), then "path=value" lines
// in path order, then a blank line. A fingerprint lcm-spy would not know prints "unknown=<hex>".

import java.io.DataInputStream;
import java.lang.reflect.Array;
import java.lang.reflect.Field;
import java.lang.reflect.Modifier;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Paths;
import java.util.Map;
import java.util.TreeMap;

public class LcmDump {
  public static void main(String[] args) throws Exception {
    // The database prints "Found N LCM types" on stdout: keep stdout for the dump.
    java.io.PrintStream stdout = System.out;
    System.setOut(System.err);
    lcm.spy.LCMTypeDatabase database = new lcm.spy.LCMTypeDatabase();
    System.setOut(stdout);
    StringBuilder out = new StringBuilder();
    for (String path : args) {
      byte[] bytes = Files.readAllBytes(Paths.get(path));
      long fingerprint = new DataInputStream(new java.io.ByteArrayInputStream(bytes)).readLong();
      Class<?> cls = database.getClassByFingerprint(fingerprint);
      if (cls == null) {
        out.append(String.format("unknown=%016x%n%n", fingerprint));
        continue;
      }
      Object message = cls.getConstructor(byte[].class).newInstance((Object) bytes);
      Map<String, String> fields = new TreeMap<>();
      dumpObject("", message, fields);
      out.append("type=").append(cls.getSimpleName()).append('\n');
      long classFingerprint = cls.getField("LCM_FINGERPRINT").getLong(null);
      out.append(String.format("fingerprint=%016x%n", classFingerprint));
      for (Map.Entry<String, String> e : fields.entrySet()) {
        out.append(e.getKey()).append('=').append(e.getValue()).append('\n');
      }
      out.append('\n');
    }
    System.out.print(out);
  }

  static void dumpObject(String prefix, Object message, Map<String, String> fields)
      throws IllegalAccessException {
    for (Field f : message.getClass().getFields()) {
      if (Modifier.isStatic(f.getModifiers())) continue;
      dumpValue(prefix + f.getName(), f.get(message), fields);
    }
  }

  static void dumpValue(String name, Object v, Map<String, String> fields)
      throws IllegalAccessException {
    if (v instanceof Double) {
      fields.put(name, String.format("d:%016x", Double.doubleToRawLongBits((Double) v)));
    } else if (v instanceof Boolean) {
      fields.put(name, ((Boolean) v) ? "1" : "0");
    } else if (v instanceof Long || v instanceof Integer || v instanceof Short
        || v instanceof Byte) {
      fields.put(name, v.toString());
    } else if (v instanceof String) {
      // LCM 1.3.1's Java reads a string's bytes as ISO-8859-1: this gives back the bytes sent.
      fields.put(name, "s:" + hex(((String) v).getBytes(StandardCharsets.ISO_8859_1)));
    } else if (v instanceof byte[]) {
      fields.put(name, "x:" + hex((byte[]) v));
    } else if (v != null && v.getClass().isArray()) {
      for (int i = 0; i < Array.getLength(v); ++i) {
        dumpValue(name + "[" + i + "]", Array.get(v, i), fields);
      }
    } else if (v != null) {
      dumpObject(name + ".", v, fields);
    }
  }

  static String hex(byte[] bytes) {
    if (bytes.length > 64) {  // length and 64-bit FNV-1a hash, as field_dump.hpp
      long hash = 0xcbf29ce484222325L;
      for (byte b : bytes) hash = (hash ^ (b & 0xff)) * 0x100000001b3L;
      return String.format("#%d:%016x", bytes.length, hash);
    }
    StringBuilder s = new StringBuilder();
    for (byte b : bytes) s.append(String.format("%02x", b & 0xff));
    return s.toString();
  }
}
