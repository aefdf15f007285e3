#include "app/settings.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace naris::app {

std::string setting_text(double v) {
  return fmt::format("{}", v);
}
std::string setting_text(int v) {
  return fmt::format("{}", v);
}

double parse_setting_double(const std::string& text, const std::string& where) {
  try {
    std::size_t used = 0;
    const double v = std::stod(text, &used);
    if (used == text.size() && std::isfinite(v)) return v;
  } catch (const std::exception&) {
  }
  fail("{}: '{}' is not a number", where, text);
}

int parse_setting_int(const std::string& text, const std::string& where) {
  try {
    std::size_t used = 0;
    const int v = std::stoi(text, &used);
    if (used == text.size()) return v;
  } catch (const std::exception&) {
  }
  fail("{}: '{}' is not a whole number", where, text);
}

Settings& Settings::push(Entry e) {
  for (const Entry& other : entries_)
    if (other.name == e.name) fail("internal: the setting '{}' is defined twice", e.name);
  entries_.push_back(std::move(e));
  return *this;
}

Settings& Settings::add(std::string name, bool& target, std::string help) {
  Entry e;
  e.name = std::move(name);
  e.help = std::move(help);
  e.kind = Kind::flag;
  e.default_text = target ? "true" : "false";
  bool* const p = &target;
  // YAML's spellings of a boolean (YAML 1.1, as yaml-cpp reads them).
  e.set = [p](const std::string& t, const std::string& w) {
    static const std::set<std::string> yes = {"true", "True", "TRUE", "yes", "Yes", "YES",
                                              "on",   "On",   "ON",   "y",   "Y"};
    static const std::set<std::string> no = {"false", "False", "FALSE", "no", "No", "NO",
                                             "off",   "Off",   "OFF",   "n",  "N"};
    if (yes.count(t)) {
      *p = true;
    } else if (no.count(t)) {
      *p = false;
    } else {
      fail("{}: '{}' is neither true nor false", w, t);
    }
  };
  return push(std::move(e));
}

Settings& Settings::add(std::string name, std::vector<std::string>& target, std::string help) {
  Entry e;
  e.name = std::move(name);
  e.help = std::move(help);
  e.kind = Kind::list;
  e.default_text = fmt::format("{}", fmt::join(target, ", "));
  auto* const p = &target;
  // Each value given adds one item; the first replaces the defaults.
  auto fresh = std::make_shared<bool>(true);
  e.set = [p, fresh](const std::string& t, const std::string&) {
    if (*fresh) p->clear();
    *fresh = false;
    p->push_back(t);
  };
  return push(std::move(e));
}

void Settings::check_last(std::function<void(double, const std::string&)> check) {
  Entry& e = entries_.back();
  // The value's own parse first (its message names the type), then the check.
  e.set = [set = e.set, check](const std::string& t, const std::string& w) {
    set(t, w);
    check(parse_setting_double(t, w), w);
  };
}

Settings& Settings::range(double lo, double hi) {
  check_last([lo, hi](double v, const std::string& w) {
    if (!(v >= lo && v <= hi)) fail("{}: {} is outside [{}, {}]", w, v, lo, hi);
  });
  return *this;
}

Settings& Settings::positive() {
  check_last([](double v, const std::string& w) {
    if (!(v > 0.0)) fail("{}: {} must be positive", w, v);
  });
  return *this;
}

Settings& Settings::non_negative() {
  check_last([](double v, const std::string& w) {
    if (!(v >= 0.0)) fail("{}: {} must not be negative", w, v);
  });
  return *this;
}

Settings& Settings::one_of(std::vector<std::string> choices) {
  Entry& e = entries_.back();
  e.help += fmt::format(" ({})", fmt::join(choices, ", "));
  e.set = [set = e.set, choices](const std::string& t, const std::string& w) {
    if (std::find(choices.begin(), choices.end(), t) == choices.end())
      fail("{}: '{}' is not one of {}", w, t, fmt::join(choices, ", "));
    set(t, w);
  };
  return *this;
}

std::string Settings::option_name(const Entry& e) {
  std::string dashed = e.name;
  std::replace(dashed.begin(), dashed.end(), '_', '-');
  if (e.kind == Kind::flag && e.default_text == "true") return "--no-" + dashed;
  return "--" + dashed;
}

void Settings::add_to(CLI::App* cmd) {
  for (const Entry& e : entries_) {
    const std::string flag = option_name(e);
    const std::string name = e.name;
    if (e.kind == Kind::flag) {
      const std::string value = e.default_text == "true" ? "false" : "true";
      cmd->add_flag_callback(
          flag,
          [this, name, value, flag] {
            given_.insert(name);
            for (const Entry& x : entries_)
              if (x.name == name) x.set(value, flag);
          },
          e.help);
      continue;
    }
    CLI::Option* o = cmd->add_option(
        flag,
        [this, name, flag](const CLI::results_t& values) {
          given_.insert(name);
          for (const Entry& x : entries_)
            if (x.name == name)
              for (const std::string& v : values) x.set(v, flag);
          return true;
        },
        e.help);
    o->type_size(1);
    if (e.kind == Kind::list)  // --seed a b, or --seed a --seed b
      o->expected(1, CLI::detail::expected_max_vector_size)
          ->allow_extra_args(true)
          ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
    else  // one value, given once
      o->expected(1)->multi_option_policy(CLI::MultiOptionPolicy::Throw);
    if (!e.default_text.empty()) o->default_str(e.default_text);
  }
}

void Settings::read(const YAML::Node& section, const std::string& where) {
  if (!section || section.IsNull()) return;
  if (!section.IsMap()) fail("{}: expected a map of settings", where);
  for (const auto& kv : section) {
    const auto key = kv.first.as<std::string>();
    const auto found = std::find_if(entries_.begin(), entries_.end(),
                                    [&](const Entry& e) { return e.name == key; });
    if (found == entries_.end()) {
      std::vector<std::string> known;
      for (const Entry& e : entries_) known.push_back(e.name);
      fail("{}: unknown setting '{}' (known: {})", where, key, fmt::join(known, ", "));
    }
    const std::string at = where + "." + key;
    const YAML::Node& v = kv.second;
    if (v.IsNull()) continue;  // as if not given
    given_.insert(key);
    if (v.IsSequence()) {
      if (found->kind != Kind::list) fail("{}: expected one value, not a list", at);
      for (const auto& item : v) {
        if (!item.IsScalar()) fail("{}: '{}' is not a valid value", at, YAML::Dump(item));
        found->set(item.as<std::string>(), at);
      }
    } else if (v.IsScalar()) {
      found->set(v.as<std::string>(), at);
    } else {
      fail("{}: '{}' is not a valid value", at, YAML::Dump(v));
    }
  }
}

}  // namespace naris::app
