#pragma once
// One table of settings per stage feeds both front doors: the stage's command-line options
// (--name, dashes for underscores) and its section of a case file (name: value), with the same
// names, defaults, help and checks. A boolean that defaults to true is switched off on the
// command line by --no-name; one that defaults to false is switched on by --name.
#include <functional>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

// Forward declarations: CLI11 and yaml-cpp are heavy headers that most includers (the stages'
// tables) never use.
namespace CLI {
class App;
}
namespace YAML {
class Node;
}

namespace naris::app {

class Settings {
 public:
  Settings() = default;
  // Entries point into the fields they set (and into this table): one table, never a copy.
  Settings(const Settings&) = delete;
  Settings& operator=(const Settings&) = delete;

  enum class Kind { value, flag, list };
  struct Entry {
    std::string name, help, default_text;
    Kind kind = Kind::value;
    // Parses and checks one value given as text; `where` names it in an error message.
    std::function<void(const std::string& text, const std::string& where)> set;
  };

  // A value read as T (double, int, std::string, or an optional of one: unset by default).
  template <class T>
  Settings& add(std::string name, T& target, std::string help);
  Settings& add(std::string name, bool& target, std::string help);
  Settings& add(std::string name, std::vector<std::string>& target, std::string help);

  // Checks on the entry just added: table.add(…).positive().
  Settings& range(double lo, double hi);
  Settings& positive();
  Settings& non_negative();
  Settings& one_of(std::vector<std::string> choices);

  // The entries as options of `cmd`.
  void add_to(CLI::App* cmd);
  // A case file's section (a map; null or absent: nothing given). Unknown keys are errors.
  void read(const YAML::Node& section, const std::string& where);
  bool given(const std::string& name) const { return given_.count(name) > 0; }
  const std::vector<Entry>& entries() const { return entries_; }
  // The command-line spelling of an entry: --name, or --no-name for a flag that defaults on.
  static std::string option_name(const Entry& e);

 private:
  Settings& push(Entry e);
  void check_last(std::function<void(double, const std::string&)> check);

  std::vector<Entry> entries_;
  std::set<std::string> given_;
};

// The text of a value as the table shows it (defaults, help).
std::string setting_text(double v);
std::string setting_text(int v);

// Parses `text` as T, or fails naming `where`.
double parse_setting_double(const std::string& text, const std::string& where);
int parse_setting_int(const std::string& text, const std::string& where);

template <class T>
Settings& Settings::add(std::string name, T& target, std::string help) {
  Entry e;
  e.name = std::move(name);
  e.help = std::move(help);
  T* const p = &target;
  if constexpr (std::is_same_v<T, double>) {
    e.default_text = setting_text(target);
    e.set = [p](const std::string& t, const std::string& w) { *p = parse_setting_double(t, w); };
  } else if constexpr (std::is_same_v<T, int>) {
    e.default_text = setting_text(target);
    e.set = [p](const std::string& t, const std::string& w) { *p = parse_setting_int(t, w); };
  } else if constexpr (std::is_same_v<T, std::string>) {
    e.default_text = target;
    e.set = [p](const std::string& t, const std::string&) { *p = t; };
  } else if constexpr (std::is_same_v<T, std::optional<double>>) {
    e.default_text = target ? setting_text(*target) : "";
    e.set = [p](const std::string& t, const std::string& w) { *p = parse_setting_double(t, w); };
  } else if constexpr (std::is_same_v<T, std::optional<int>>) {
    e.default_text = target ? setting_text(*target) : "";
    e.set = [p](const std::string& t, const std::string& w) { *p = parse_setting_int(t, w); };
  } else if constexpr (std::is_same_v<T, std::optional<std::string>>) {
    e.default_text = target ? *target : "";
    e.set = [p](const std::string& t, const std::string&) { *p = t; };
  } else {
    static_assert(sizeof(T) == 0, "no setting of this type");
  }
  return push(std::move(e));
}

}  // namespace naris::app
