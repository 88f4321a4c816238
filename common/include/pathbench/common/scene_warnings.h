#pragma once
// What reading a scene has to say without failing: a warning (something in the file is
// not modelled and was ignored, triangles were dropped, coordinates were rounded) or a
// note (a default light was added). Printed to stderr as "warning: ..." / "note: ...",
// unless the calling thread collects them (SceneWarningCollector): the Python module
// turns them into Python warnings.
#include <string>
#include <vector>

namespace pb {

enum class SceneMessage { Warning, Note };

// Prints, or hands to this thread's collector, one message (without the "warning: "
// prefix or a final newline).
void scene_message(SceneMessage kind, const std::string& text);
inline void scene_warning(const std::string& text) { scene_message(SceneMessage::Warning, text); }
inline void scene_note(const std::string& text) { scene_message(SceneMessage::Note, text); }

// While one lives, this thread's scene messages are kept instead of printed (nested
// collectors: the innermost keeps them).
class SceneWarningCollector {
 public:
  struct Message {
    SceneMessage kind;
    std::string text;
  };
  SceneWarningCollector();
  ~SceneWarningCollector();
  SceneWarningCollector(const SceneWarningCollector&) = delete;
  SceneWarningCollector& operator=(const SceneWarningCollector&) = delete;
  const std::vector<Message>& messages() const { return messages_; }

 private:
  friend void scene_message(SceneMessage, const std::string&);
  std::vector<Message> messages_;
  SceneWarningCollector* outer_;
};

}  // namespace pb
