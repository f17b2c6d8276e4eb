// sg-keygen: makes the lab key that signs every command to the arm (docs/security.md): 32 random
// bytes as 64 hex characters in a file of mode 0600. Copy the same file to every lab machine.
//
//   sg-keygen                          # $SG_LAB_KEY, else ~/.config/stereograsp/lab.key
//   sg-keygen /tmp/session/lab.key     # a key of one's own (then --key or SG_LAB_KEY)
//   sg-keygen --force                  # replace an existing key (every machine needs the new one)

#include <cstdio>

#include "auth/lab_key.hpp"
#include "common/program.hpp"

int main(int argc, char** argv) {
  CLI::App app{"Writes a new lab key (mode 0600) that signs and checks commands to the arm.",
               "sg-keygen"};
  std::string path;
  bool force = false;
  app.add_option("PATH", path,
                 "key file to write (default: $SG_LAB_KEY, else ~/.config/stereograsp/lab.key)");
  app.add_flag("--force", force, "replace an existing key file");
  return sg::run_program(app, argc, argv, [&] {
    if (path.empty()) path = sg::auth::default_key_path();
    sg::auth::write_new_key_file(path, force);
    std::printf("wrote a new lab key to %s\ncopy it to every lab machine with mode 0600 "
                "(e.g. scp -p), or give each program --key PATH\n",
                path.c_str());
    return 0;
  });
}
